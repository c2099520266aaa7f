// Who may call what: bearer tokens with roles, the one table of the role each RPC needs, the owners of scenes
// and the scripters granted each hardware device. No gRPC here: the interceptor (rpc/auth_interceptor.h) and the HTTP
// gateway both call Authorizer, so a call is judged the same way whichever port it came in on.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace graspsim::auth {

// viewer ⊂ scripter ⊂ admin; gateway ⊂ admin. kPublic: no token needed (health checks).
enum class Role { kPublic, kViewer, kScripter, kGateway, kAdmin };
const char* RoleName(Role role);
std::optional<Role> ParseRole(std::string_view text);
// Whether a caller holding `have` may call a method that needs `need`.
bool RoleAllows(Role have, Role need);

// What a method does with the scene its request names (field scene_id, or header.scene_id).
enum class SceneAccess { kNone, kRead, kWrite };

struct MethodRule {
  Role role;
  SceneAccess scene;
  bool device_grant = false;  // the request's device_id must be granted to the caller (gateway commands)
};

// Full method name ("/graspsim.v1.SceneService/GetScene") → rule. The one table; a method missing here is
// refused (tests/cpp/auth checks that every method of every proto service has an entry).
const std::map<std::string, MethodRule, std::less<>>& RoleTable();

struct Identity {
  std::string name;  // the token's name, or "cert:<common name>" for a gateway known by its client certificate
  Role role = Role::kPublic;
};

// "sha256:<salt>:<hex of SHA-256(salt ':' secret)>", the stored form of a token.
std::string HashToken(std::string_view salt, std::string_view secret);
std::string RandomSalt();

enum class Verdict { kAllow, kUnauthenticated, kPermissionDenied };
struct Decision {
  Verdict verdict = Verdict::kAllow;
  std::string message;
  Identity who;
};

class AuthStore;

class Authorizer {
 public:
  Authorizer();
  ~Authorizer();

  // Keeps what AuthService changes (tokens added or revoked, device grants) and the owners and shares of scenes
  // in <directory>/auth.sqlite (auth/auth_store.h), and loads what an earlier run kept. Call once, after
  // LoadTokenFile and before serving: a stored revocation also revokes a token of the file with that name.
  void OpenStore(const std::string& directory);
  // Parses a token file (docs/security.md): "<role> <name> <secret | sha256:salt:hex>" and
  // "grant <device_id> <name>" lines, '#' comments. Throws Error(kInvalidArgument) naming file, line and field.
  void LoadTokenFile(const std::string& path);
  // keep: also into the store (AuthService); the token file's entries are read again at every start instead.
  void AddToken(Role role, const std::string& name, const std::string& secret_or_hash, const std::string& where,
                bool keep = false);
  bool RevokeToken(const std::string& name);  // false: no such name
  void GrantDevice(const std::string& device_id, const std::string& name, bool keep = false);
  size_t token_count() const;

  // The caller of a bearer token ("" = none), or nullopt.
  std::optional<Identity> Find(std::string_view token) const;

  // The role check for one call: token (or a verified client certificate's common name, which counts as role
  // gateway) against the method's rule.
  Decision Authorize(std::string_view method, std::string_view bearer_token, std::string_view cert_name) const;
  // The scene and device checks, once the request is known. A scene that does not exist and a scene of
  // somebody else get the same answer, so that neither reveals the other.
  Decision AuthorizeRequest(const Identity& who, const MethodRule& rule, std::string_view scene_id,
                            std::string_view device_id) const;

  void SetOwner(const std::string& scene_id, const std::string& owner);
  void ForgetScene(const std::string& scene_id);
  bool CanRead(const Identity& who, std::string_view scene_id) const;
  // Shares a scene for reading; only its owner or an admin may. Returns false when `who` may not.
  bool Share(const Identity& who, const std::string& scene_id, const std::string& with);

 private:
  struct Token {
    std::string name, salt, hash;
    Role role;
  };
  struct Owner {
    std::string owner;
    std::set<std::string> readers;
  };
  mutable std::mutex mutex_;
  std::unique_ptr<AuthStore> store_;  // null: nothing survives a restart
  std::vector<Token> tokens_;
  std::map<std::string, std::set<std::string>, std::less<>> device_grants_;
  std::map<std::string, Owner, std::less<>> scenes_;
};

// Extracts the token of "Bearer <token>" ("" when the header is not of that form).
std::string_view BearerToken(std::string_view authorization_header);

}  // namespace graspsim::auth
