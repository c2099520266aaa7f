// Authorizer: token hashing, lookup, revocation, the token file's errors, role order, scene owners and grants.
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include <gtest/gtest.h>

#include "auth/auth.h"
#include "core/error.h"
#include "core/sha256.h"

namespace graspsim::auth {
namespace {

std::string WriteFile(const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("graspsim-tokens-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
                     ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::ofstream(path) << text;
  return path.string();
}

std::string LoadError(const std::string& text) {
  Authorizer authorizer;
  try {
    authorizer.LoadTokenFile(WriteFile(text));
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::kInvalidArgument);
    return error.what();
  }
  return "";
}

TEST(AuthTokenStore, HashIsSha256OfSaltColonSecret) {
  // An independent reference: the SHA-256 of "salt:secret" (core/sha256 is checked against FIPS vectors).
  EXPECT_EQ(HashToken("abc", "s3cret"), "sha256:abc:" + Sha256Hex("abc:s3cret"));
  EXPECT_NE(HashToken("abc", "s3cret"), HashToken("abd", "s3cret"));
  EXPECT_EQ(RandomSalt().size(), 32u);
  EXPECT_NE(RandomSalt(), RandomSalt());
}

TEST(AuthTokenStore, FindsPlainAndHashedEntriesAndForgetsRevoked) {
  const std::string file = WriteFile(
      "# comment line\n"
      "\n"
      "scripter alice alice-secret-0123456789   # trailing comment\n"
      "viewer vera " + HashToken("salt1", "vera-secret-0123456789") + "\n"
      "grant pg70-1 alice\n");
  Authorizer authorizer;
  authorizer.LoadTokenFile(file);
  EXPECT_EQ(authorizer.token_count(), 2u);
  const auto alice = authorizer.Find("alice-secret-0123456789");
  ASSERT_TRUE(alice);
  EXPECT_EQ(alice->name, "alice");
  EXPECT_EQ(alice->role, Role::kScripter);
  const auto vera = authorizer.Find("vera-secret-0123456789");
  ASSERT_TRUE(vera);
  EXPECT_EQ(vera->role, Role::kViewer);
  EXPECT_FALSE(authorizer.Find("vera-secret-012345678"));   // one character short
  EXPECT_FALSE(authorizer.Find(HashToken("salt1", "vera-secret-0123456789")));  // the stored form is no token
  EXPECT_FALSE(authorizer.Find(""));
  EXPECT_TRUE(authorizer.RevokeToken("alice"));
  EXPECT_FALSE(authorizer.Find("alice-secret-0123456789"));
  EXPECT_FALSE(authorizer.RevokeToken("alice"));
  EXPECT_TRUE(authorizer.Find("vera-secret-0123456789"));
}

TEST(AuthTokenStore, FileErrorsNameTheLineAndTheField) {
  const std::string ok = "viewer vera vera-secret-0123456789\n";
  std::string error = LoadError(ok + "boss carol carol-secret-0123456789\n");
  EXPECT_NE(error.find(":2: role: 'boss' is not one of viewer, scripter, gateway, admin"), std::string::npos) << error;
  error = LoadError(ok + "# fine\nscripter carol\n");
  EXPECT_NE(error.find(":3: expected 3 fields"), std::string::npos) << error;
  EXPECT_NE(error.find("got 2"), std::string::npos) << error;
  error = LoadError("scripter carol short\n");
  EXPECT_NE(error.find(":1: token: 5 characters; a secret needs at least 16"), std::string::npos) << error;
  error = LoadError("scripter car/ol carol-secret-0123456789\n");
  EXPECT_NE(error.find(":1: name: 'car/ol'"), std::string::npos) << error;
  error = LoadError("scripter carol sha256:salt:abc\n");
  EXPECT_NE(error.find(":1: token: 'sha256:salt:abc' is not sha256:<salt>:<64 lowercase hex digits>"),
            std::string::npos) << error;
  error = LoadError(ok + "scripter vera other-secret-0123456789\n");
  EXPECT_NE(error.find(":2: name: 'vera' is already the name of a token"), std::string::npos) << error;
  error = LoadError("grant pg70 bad/name\n");
  EXPECT_NE(error.find(":1: name: 'bad/name'"), std::string::npos) << error;
  Authorizer authorizer;
  try {
    authorizer.LoadTokenFile("/nonexistent/tokens");
    FAIL() << "a missing file loaded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--token-file: cannot read '/nonexistent/tokens'"), std::string::npos);
  }
}

TEST(AuthRoles, OrderAndTableChecks) {
  EXPECT_TRUE(RoleAllows(Role::kScripter, Role::kViewer));
  EXPECT_TRUE(RoleAllows(Role::kAdmin, Role::kGateway));
  EXPECT_TRUE(RoleAllows(Role::kViewer, Role::kPublic));
  EXPECT_FALSE(RoleAllows(Role::kViewer, Role::kScripter));
  EXPECT_FALSE(RoleAllows(Role::kGateway, Role::kViewer));
  EXPECT_FALSE(RoleAllows(Role::kScripter, Role::kGateway));
  EXPECT_FALSE(RoleAllows(Role::kScripter, Role::kAdmin));

  Authorizer authorizer;
  authorizer.AddToken(Role::kViewer, "vera", "vera-secret-0123456789", "");
  authorizer.AddToken(Role::kScripter, "sam", "sam-secret-01234567890", "");
  EXPECT_EQ(authorizer.Authorize("/graspsim.v1.SceneService/ListScenes", "", "").verdict, Verdict::kUnauthenticated);
  EXPECT_EQ(authorizer.Authorize("/graspsim.v1.SceneService/ListScenes", "wrong-token-000000", "").verdict,
            Verdict::kUnauthenticated);
  EXPECT_EQ(authorizer.Authorize("/grpc.health.v1.Health/Check", "", "").verdict, Verdict::kAllow);
  EXPECT_EQ(authorizer.Authorize("/graspsim.v1.SceneService/GetScene", "vera-secret-0123456789", "").verdict,
            Verdict::kAllow);
  const Decision denied = authorizer.Authorize("/graspsim.v1.SceneService/CreateScene", "vera-secret-0123456789", "");
  EXPECT_EQ(denied.verdict, Verdict::kPermissionDenied);
  EXPECT_EQ(denied.message, "/graspsim.v1.SceneService/CreateScene needs role scripter; 'vera' is viewer");
  EXPECT_EQ(authorizer.Authorize("/graspsim.v1.SceneService/NoSuchMethod", "sam-secret-01234567890", "").verdict,
            Verdict::kPermissionDenied);
  // A verified client certificate stands for a gateway, and nothing more.
  const Decision cert = authorizer.Authorize("/graspsim.v1.GatewayService/Connect", "", "gateway-1");
  EXPECT_EQ(cert.verdict, Verdict::kAllow);
  EXPECT_EQ(cert.who.name, "cert:gateway-1");
  EXPECT_EQ(authorizer.Authorize("/graspsim.v1.SceneService/GetScene", "", "gateway-1").verdict,
            Verdict::kPermissionDenied);
}

TEST(AuthOwners, ForeignAndMissingScenesLookTheSame) {
  Authorizer authorizer;
  const Identity alice{"alice", Role::kScripter}, bob{"bob", Role::kScripter}, root{"root", Role::kAdmin};
  const MethodRule read{Role::kViewer, SceneAccess::kRead}, write{Role::kScripter, SceneAccess::kWrite};
  authorizer.SetOwner("s1", "alice");
  EXPECT_EQ(authorizer.AuthorizeRequest(alice, write, "s1", "").verdict, Verdict::kAllow);
  const Decision foreign = authorizer.AuthorizeRequest(bob, read, "s1", "");
  const Decision missing = authorizer.AuthorizeRequest(bob, read, "s2", "");
  EXPECT_EQ(foreign.verdict, Verdict::kPermissionDenied);
  EXPECT_EQ(missing.verdict, Verdict::kPermissionDenied);
  EXPECT_EQ(foreign.message, "scene_id: 's1' does not exist or is not yours");
  EXPECT_EQ(missing.message, "scene_id: 's2' does not exist or is not yours");
  EXPECT_FALSE(authorizer.Share(bob, "s1", "bob"));  // not the owner
  EXPECT_TRUE(authorizer.Share(alice, "s1", "bob"));
  EXPECT_EQ(authorizer.AuthorizeRequest(bob, read, "s1", "").verdict, Verdict::kAllow);
  EXPECT_EQ(authorizer.AuthorizeRequest(bob, write, "s1", "").verdict, Verdict::kPermissionDenied);
  EXPECT_TRUE(authorizer.CanRead(bob, "s1"));
  EXPECT_EQ(authorizer.AuthorizeRequest(root, write, "s1", "").verdict, Verdict::kAllow);
  authorizer.ForgetScene("s1");
  EXPECT_FALSE(authorizer.CanRead(alice, "s1"));
  // Devices: only granted names; admin always.
  const MethodRule command{Role::kScripter, SceneAccess::kNone, true};
  authorizer.GrantDevice("pg70", "alice");
  EXPECT_EQ(authorizer.AuthorizeRequest(alice, command, "", "pg70").verdict, Verdict::kAllow);
  EXPECT_EQ(authorizer.AuthorizeRequest(bob, command, "", "pg70").message, "device_id: 'pg70' is not granted to 'bob'");
  EXPECT_EQ(authorizer.AuthorizeRequest(root, command, "", "pg70").verdict, Verdict::kAllow);
}

}  // namespace
}  // namespace graspsim::auth

namespace graspsim::auth {
namespace {

TEST(AuthStore, WhatTheRpcsChangeSurvivesAReopen) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("graspsim-auth-store-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                    "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const std::string file = WriteFile("scripter alice alice-secret-0123456789\nscripter bob bob-secret-01234567890\n");
  const Identity alice{"alice", Role::kScripter}, bob{"bob", Role::kScripter};
  {
    Authorizer first;
    first.LoadTokenFile(file);
    first.OpenStore(dir.string());
    first.AddToken(Role::kViewer, "carol", "carol-secret-0123456789", "", /*keep=*/true);
    first.AddToken(Role::kViewer, "dave", "dave-secret-01234567890", "");  // not kept
    EXPECT_TRUE(first.RevokeToken("bob"));
    first.SetOwner("s1", "alice");
    first.SetOwner("s2", "alice");
    EXPECT_TRUE(first.Share(alice, "s1", "carol"));
    first.ForgetScene("s2");
    first.GrantDevice("pg70", "alice", /*keep=*/true);
  }
  Authorizer second;
  second.LoadTokenFile(file);
  second.OpenStore(dir.string());
  EXPECT_TRUE(second.Find("alice-secret-0123456789"));
  EXPECT_FALSE(second.Find("bob-secret-01234567890"));  // the revocation outlives the file's entry
  ASSERT_TRUE(second.Find("carol-secret-0123456789"));
  EXPECT_EQ(second.Find("carol-secret-0123456789")->role, Role::kViewer);
  EXPECT_FALSE(second.Find("dave-secret-01234567890"));
  EXPECT_TRUE(second.CanRead(alice, "s1"));
  EXPECT_TRUE(second.CanRead({"carol", Role::kViewer}, "s1"));
  EXPECT_FALSE(second.CanRead(alice, "s2"));
  const MethodRule command{Role::kScripter, SceneAccess::kNone, true};
  EXPECT_EQ(second.AuthorizeRequest(alice, command, "", "pg70").verdict, Verdict::kAllow);
  EXPECT_EQ(std::filesystem::status(dir / "auth.sqlite").permissions() & std::filesystem::perms::others_read,
            std::filesystem::perms::none);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace graspsim::auth
