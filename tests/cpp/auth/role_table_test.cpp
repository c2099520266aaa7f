// The role table covers every method of every service in the protos. The list of methods comes from the
// generated descriptors (linked in through the *.pb.h below), so a new RPC without a row fails here.
#include <algorithm>
#include <filesystem>
#include <set>
#include <string>

#include <google/protobuf/descriptor.h>
#include <gtest/gtest.h>

#include "auth/auth.h"
#include "graspsim/v1/auth.pb.h"
#include "graspsim/v1/gateway.pb.h"
#include "graspsim/v1/grasp.pb.h"
#include "graspsim/v1/perception.pb.h"
#include "graspsim/v1/recording.pb.h"
#include "graspsim/v1/scene.pb.h"
#include "graspsim/v1/tactile.pb.h"
#include "source_tree.h"

namespace graspsim::auth {
namespace {

TEST(AuthRoleTable, EveryProtoMethodHasARowAndEveryRowAMethod) {
  // One message of each file forces its descriptor into the pool; then walk the files' services.
  const google::protobuf::FileDescriptor* files[] = {
      v1::WhoAmIRequest::descriptor()->file(),     v1::DeviceCommand::descriptor()->file(),
      v1::GetGraspSetRequest::descriptor()->file(), v1::SegmentSceneRequest::descriptor()->file(),
      v1::GetSceneRequest::descriptor()->file(),    v1::SampleRequest::descriptor()->file(),
      v1::StartRecordingRequest::descriptor()->file()};
  std::set<std::string> methods;
  for (const auto* file : files) {
    for (int s = 0; s < file->service_count(); ++s) {
      const auto* service = file->service(s);
      for (int m = 0; m < service->method_count(); ++m) {
        methods.insert("/" + service->full_name() + "/" + service->method(m)->name());
      }
    }
  }
  // Every .proto of the API in the source tree is among them: a new file with a service cannot be missed.
  const auto* pool = google::protobuf::DescriptorPool::generated_pool();
  const auto proto_dir = std::filesystem::path(SourceTree()) / "proto/graspsim/v1";
  int proto_files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(proto_dir)) {
    if (entry.path().extension() != ".proto") continue;
    ++proto_files;
    const std::string name = "graspsim/v1/" + entry.path().filename().string();
    const auto* file = pool->FindFileByName(name);
    ASSERT_NE(file, nullptr) << name << " is not linked in: add one of its messages to files[] above";
    if (file->service_count() > 0) {
      EXPECT_NE(std::find(std::begin(files), std::end(files), file), std::end(files)) << name << ": add it to files[]";
    }
  }
  EXPECT_GE(proto_files, 7);
  ASSERT_GE(methods.size(), 39u);  // the API had 39 methods when this test was written
  const auto& table = RoleTable();
  for (const auto& method : methods) EXPECT_TRUE(table.contains(method)) << method << " has no row in auth/role_table.cpp";
  for (const auto& [method, rule] : table) {
    if (method.starts_with("/graspsim.")) {
      EXPECT_TRUE(methods.contains(method)) << method << ": no such RPC";
    }
  }
}

TEST(AuthRoleTable, WritesNeedScripterAndSceneOwnership) {
  // Spot checks of the table's intent: every method that changes a scene needs scripter and write access.
  const auto& table = RoleTable();
  for (const char* method : {"CreateScene", "DeleteScene", "UploadFile", "AddObject", "SetBodyPoses", "StepSimulation"}) {
    const auto& rule = table.at(std::string("/graspsim.v1.SceneService/") + method);
    EXPECT_EQ(rule.role, Role::kScripter) << method;
    if (std::string(method) != "CreateScene") {
      EXPECT_EQ(rule.scene, SceneAccess::kWrite) << method;
    }
  }
  EXPECT_EQ(table.at("/graspsim.v1.SceneService/GetScene").scene, SceneAccess::kRead);
  EXPECT_TRUE(table.at("/graspsim.v1.GatewayService/SendCommand").device_grant);
  EXPECT_EQ(table.at("/graspsim.v1.GatewayService/Connect").role, Role::kGateway);
  EXPECT_EQ(table.at("/graspsim.v1.AuthService/RevokeToken").role, Role::kAdmin);
}

TEST(AuthRoleTable, HardwareCommandsAreAllInGatewayService) {
  // With tokens off the interceptor is created only for GatewayService and AuthService calls
  // (rpc/auth_interceptor.cpp): a device grant anywhere else would go unlogged there.
  for (const auto& [method, rule] : RoleTable()) {
    if (rule.device_grant) {
      EXPECT_TRUE(method.starts_with("/graspsim.v1.GatewayService/")) << method;
    }
  }
}

}  // namespace
}  // namespace graspsim::auth
