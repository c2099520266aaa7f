#include <fstream>
#include <sstream>

#include <openssl/crypto.h>
#include <openssl/rand.h>

#include "auth/auth.h"
#include "auth/auth_store.h"
#include "core/error.h"
#include "core/sha256.h"

namespace graspsim::auth {
namespace {

constexpr std::string_view kHashPrefix = "sha256:";
// The same words for a scene that does not exist and one of somebody else: neither may be told apart.
constexpr char kNoScene[] = "' does not exist or is not yours";

bool ValidName(std::string_view name) {
  if (name.empty() || name.size() > 128) return false;
  for (char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.' && c != '@') return false;
  }
  return true;
}

bool IsHex(std::string_view text) { return text.find_first_not_of("0123456789abcdef") == std::string_view::npos; }

}  // namespace

const char* RoleName(Role role) {
  switch (role) {
    case Role::kPublic: return "public";
    case Role::kViewer: return "viewer";
    case Role::kScripter: return "scripter";
    case Role::kGateway: return "gateway";
    case Role::kAdmin: return "admin";
  }
  return "?";
}

std::optional<Role> ParseRole(std::string_view text) {
  for (Role role : {Role::kViewer, Role::kScripter, Role::kGateway, Role::kAdmin}) {
    if (text == RoleName(role)) return role;
  }
  return std::nullopt;
}

bool RoleAllows(Role have, Role need) {
  if (need == Role::kPublic || have == Role::kAdmin) return true;
  if (need == Role::kViewer) return have == Role::kViewer || have == Role::kScripter;
  return have == need;
}

std::string HashToken(std::string_view salt, std::string_view secret) {
  std::string input(salt);
  input += ':';
  input += secret;
  return std::string(kHashPrefix) + std::string(salt) + ":" + Sha256Hex(input);
}

std::string RandomSalt() {
  unsigned char bytes[16];
  if (RAND_bytes(bytes, sizeof bytes) != 1) throw Error(ErrorCode::kInternal, "RAND_bytes failed");
  static constexpr char kHex[] = "0123456789abcdef";
  std::string salt;
  for (unsigned char b : bytes) {
    salt += kHex[b >> 4];
    salt += kHex[b & 15];
  }
  return salt;
}

std::string_view BearerToken(std::string_view header) {
  constexpr std::string_view kBearer = "Bearer ";
  if (header.size() <= kBearer.size() || header.substr(0, kBearer.size()) != kBearer) return {};
  return header.substr(kBearer.size());
}

Authorizer::Authorizer() = default;
Authorizer::~Authorizer() = default;

void Authorizer::OpenStore(const std::string& directory) {
  auto store = std::make_unique<AuthStore>(directory);
  std::lock_guard lock(mutex_);
  store->ForEach("SELECT name, role, hash FROM tokens", [&](const std::vector<std::string>& row) {
    const auto role = ParseRole(row[1]);
    const size_t colon = row[2].find(':', kHashPrefix.size());
    if (!role || colon == std::string::npos) return;  // written by this code; a damaged row is skipped
    std::erase_if(tokens_, [&](const Token& t) { return t.name == row[0]; });  // the newer, stored one wins
    tokens_.push_back(Token{row[0], row[2].substr(kHashPrefix.size(), colon - kHashPrefix.size()), row[2], *role});
  });
  store->ForEach("SELECT name FROM revoked", [&](const std::vector<std::string>& row) {
    std::erase_if(tokens_, [&](const Token& t) { return t.name == row[0]; });
  });
  store->ForEach("SELECT scene_id, owner FROM scenes",
                 [&](const std::vector<std::string>& row) { scenes_[row[0]].owner = row[1]; });
  store->ForEach("SELECT scene_id, name FROM shares",
                 [&](const std::vector<std::string>& row) { scenes_[row[0]].readers.insert(row[1]); });
  store->ForEach("SELECT device_id, name FROM grants",
                 [&](const std::vector<std::string>& row) { device_grants_[row[0]].insert(row[1]); });
  store_ = std::move(store);
}

void Authorizer::AddToken(Role role, const std::string& name, const std::string& secret_or_hash,
                          const std::string& where, bool keep) {
  if (!ValidName(name)) {
    ThrowInvalidArgument(where + "name: '" + name.substr(0, 80) + "' is not 1-128 letters, digits or - _ . @");
  }
  Token token{name, "", "", role};
  if (secret_or_hash.starts_with(kHashPrefix)) {
    const std::string rest = secret_or_hash.substr(kHashPrefix.size());
    const size_t colon = rest.find(':');
    const std::string hex = colon == std::string::npos ? "" : rest.substr(colon + 1);
    if (colon == std::string::npos || colon == 0 || hex.size() != 64 || !IsHex(hex)) {
      ThrowInvalidArgument(where + "token: '" + secret_or_hash.substr(0, 100) +
                           "' is not sha256:<salt>:<64 lowercase hex digits>");
    }
    token.salt = rest.substr(0, colon);
    token.hash = secret_or_hash;
  } else {
    if (secret_or_hash.size() < 16) {
      ThrowInvalidArgument(where + "token: " + std::to_string(secret_or_hash.size()) +
                           " characters; a secret needs at least 16");
    }
    token.salt = RandomSalt();
    token.hash = HashToken(token.salt, secret_or_hash);
  }
  std::lock_guard lock(mutex_);
  for (const auto& t : tokens_) {
    if (t.name == name) ThrowInvalidArgument(where + "name: '" + name + "' is already the name of a token");
  }
  if (keep && store_) {
    store_->Run("INSERT OR REPLACE INTO tokens (name, role, hash) VALUES (?1, ?2, ?3)", {name, RoleName(role), token.hash});
    store_->Run("DELETE FROM revoked WHERE name = ?1", {name});
  }
  tokens_.push_back(std::move(token));
}

void Authorizer::LoadTokenFile(const std::string& path) {
  std::ifstream file(path);
  if (!file) ThrowInvalidArgument("--token-file: cannot read '" + path + "'");
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    const std::string where = "--token-file: " + path + ":" + std::to_string(number) + ": ";
    std::istringstream words(line.substr(0, line.find('#')));
    std::vector<std::string> fields;
    for (std::string word; words >> word;) fields.push_back(word);
    if (fields.empty()) continue;
    if (fields.size() != 3) {
      ThrowInvalidArgument(where + "expected 3 fields ('<role> <name> <token>' or 'grant <device_id> <name>'), got " +
                           std::to_string(fields.size()));
    }
    if (fields[0] == "grant") {
      if (!ValidName(fields[2])) ThrowInvalidArgument(where + "name: '" + fields[2].substr(0, 80) + "' is not a token name");
      GrantDevice(fields[1], fields[2]);
      continue;
    }
    const auto role = ParseRole(fields[0]);
    if (!role) {
      ThrowInvalidArgument(where + "role: '" + fields[0].substr(0, 80) +
                           "' is not one of viewer, scripter, gateway, admin, grant");
    }
    AddToken(*role, fields[1], fields[2], where);
  }
}

bool Authorizer::RevokeToken(const std::string& name) {
  std::lock_guard lock(mutex_);
  if (std::erase_if(tokens_, [&](const Token& t) { return t.name == name; }) == 0) return false;
  if (store_) {
    store_->Run("DELETE FROM tokens WHERE name = ?1", {name});
    store_->Run("INSERT OR IGNORE INTO revoked (name) VALUES (?1)", {name});
  }
  return true;
}

void Authorizer::GrantDevice(const std::string& device_id, const std::string& name, bool keep) {
  std::lock_guard lock(mutex_);
  if (keep && store_) store_->Run("INSERT OR IGNORE INTO grants (device_id, name) VALUES (?1, ?2)", {device_id, name});
  device_grants_[device_id].insert(name);
}

size_t Authorizer::token_count() const {
  std::lock_guard lock(mutex_);
  return tokens_.size();
}

std::optional<Identity> Authorizer::Find(std::string_view secret) const {
  if (secret.empty()) return std::nullopt;
  std::lock_guard lock(mutex_);
  for (const auto& token : tokens_) {
    const std::string hash = HashToken(token.salt, secret);
    if (hash.size() == token.hash.size() && CRYPTO_memcmp(hash.data(), token.hash.data(), hash.size()) == 0) {
      return Identity{token.name, token.role};
    }
  }
  return std::nullopt;
}

Decision Authorizer::Authorize(std::string_view method, std::string_view bearer_token,
                               std::string_view cert_name) const {
  const auto& table = RoleTable();
  const auto rule = table.find(method);
  if (rule == table.end()) {
    return {Verdict::kPermissionDenied, std::string(method) + ": no rule in the role table (auth/role_table.cpp)", {}};
  }
  std::optional<Identity> who = Find(bearer_token);
  if (!who && !cert_name.empty()) who = Identity{"cert:" + std::string(cert_name), Role::kGateway};
  if (!who) {
    if (rule->second.role == Role::kPublic) return {Verdict::kAllow, "", {}};
    return {Verdict::kUnauthenticated,
            bearer_token.empty() ? "no bearer token (metadata authorization: Bearer <token>)"
                                 : "the bearer token is not valid (unknown or revoked)",
            {}};
  }
  if (!RoleAllows(who->role, rule->second.role)) {
    return {Verdict::kPermissionDenied,
            std::string(method) + " needs role " + RoleName(rule->second.role) + "; '" + who->name + "' is " +
                RoleName(who->role),
            *who};
  }
  return {Verdict::kAllow, "", *who};
}

Decision Authorizer::AuthorizeRequest(const Identity& who, const MethodRule& rule, std::string_view scene_id,
                                      std::string_view device_id) const {
  if (who.role == Role::kAdmin) return {Verdict::kAllow, "", who};
  std::lock_guard lock(mutex_);
  if (rule.scene != SceneAccess::kNone && !scene_id.empty()) {
    const auto scene = scenes_.find(scene_id);
    const bool allowed = scene != scenes_.end() &&
                         (scene->second.owner == who.name ||
                          (rule.scene == SceneAccess::kRead && scene->second.readers.contains(who.name)));
    if (!allowed) return {Verdict::kPermissionDenied, "scene_id: '" + std::string(scene_id) + kNoScene, who};
  }
  if (rule.device_grant) {
    const auto grant = device_grants_.find(device_id);
    if (grant == device_grants_.end() || !grant->second.contains(who.name)) {
      return {Verdict::kPermissionDenied,
              "device_id: '" + std::string(device_id) + "' is not granted to '" + who.name + "'", who};
    }
  }
  return {Verdict::kAllow, "", who};
}

void Authorizer::SetOwner(const std::string& scene_id, const std::string& owner) {
  std::lock_guard lock(mutex_);
  if (store_) {
    store_->Run("INSERT OR REPLACE INTO scenes (scene_id, owner) VALUES (?1, ?2)", {scene_id, owner});
    store_->Run("DELETE FROM shares WHERE scene_id = ?1", {scene_id});
  }
  scenes_[scene_id] = Owner{owner, {}};
}

void Authorizer::ForgetScene(const std::string& scene_id) {
  std::lock_guard lock(mutex_);
  if (store_) {
    store_->Run("DELETE FROM scenes WHERE scene_id = ?1", {scene_id});
    store_->Run("DELETE FROM shares WHERE scene_id = ?1", {scene_id});
  }
  scenes_.erase(scene_id);
}

bool Authorizer::CanRead(const Identity& who, std::string_view scene_id) const {
  if (who.role == Role::kAdmin) return true;
  std::lock_guard lock(mutex_);
  const auto scene = scenes_.find(scene_id);
  return scene != scenes_.end() && (scene->second.owner == who.name || scene->second.readers.contains(who.name));
}

bool Authorizer::Share(const Identity& who, const std::string& scene_id, const std::string& with) {
  std::lock_guard lock(mutex_);
  const auto scene = scenes_.find(scene_id);
  if (scene == scenes_.end() || (who.role != Role::kAdmin && scene->second.owner != who.name)) return false;
  if (store_) store_->Run("INSERT OR IGNORE INTO shares (scene_id, name) VALUES (?1, ?2)", {scene_id, with});
  scene->second.readers.insert(with);
  return true;
}

}  // namespace graspsim::auth
