// LoadMeshFile: a mesh file parsed by graspsim-mesh-import in a child process (world/mesh_import.h says why).
//
// The wire between the two is one Unix socket pair (send with MSG_NOSIGNAL: a child that died never raises
// SIGPIPE in the server). Request: field, path, scale, triangle limit, file bytes. Answer: 0, vertex and
// triangle counts and the raw arrays; or 1, an ErrorCode and the message. The child reads the whole request
// before it answers, so the server writes all, then reads all.
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/mesh.h"
#include "world/loaders.h"
#include "world/mesh_import.h"
#include "world/parsed_mesh_cache.h"

extern char** environ;

namespace graspsim {
namespace {

constexpr char kMagic[4] = {'G', 'S', 'M', '1'};

void PutBytes(std::string* out, const void* data, size_t size) { out->append(static_cast<const char*>(data), size); }
template <typename T>
void Put(std::string* out, const T& value) { PutBytes(out, &value, sizeof(T)); }
void PutText(std::string* out, std::string_view text) {
  Put<uint64_t>(out, text.size());
  out->append(text);
}

// Reads from a buffer; false once it runs short (a truncated request or answer).
struct Reader {
  std::string_view data;
  bool Bytes(void* out, size_t size) {
    if (data.size() < size) return false;
    std::memcpy(out, data.data(), size);
    data.remove_prefix(size);
    return true;
  }
  template <typename T>
  bool Get(T* value) { return Bytes(value, sizeof(T)); }
  bool Text(std::string_view* text) {
    uint64_t size = 0;
    if (!Get(&size) || data.size() < size) return false;
    *text = data.substr(0, size);
    data.remove_prefix(size);
    return true;
  }
};

bool WriteAll(int fd, std::string_view data) {
  while (!data.empty()) {
    const ssize_t n = send(fd, data.data(), data.size(), MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data.remove_prefix(static_cast<size_t>(n));
  }
  return true;
}

// Until end of file, or false when `deadline` passes first (no deadline: wait as long as it takes).
bool ReadAll(int fd, std::string* data, std::optional<std::chrono::steady_clock::time_point> deadline = {}) {
  char buffer[1 << 16];
  for (;;) {
    if (deadline) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(*deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return false;
      pollfd ready{fd, POLLIN, 0};
      const int polled = poll(&ready, 1, int(std::min<int64_t>(left.count(), 1000)));
      if (polled < 0 && errno != EINTR) return true;
      if (polled <= 0) continue;
    }
    const ssize_t n = read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return true;
    data->append(buffer, static_cast<size_t>(n));
  }
}

// How long a file may take to parse: far above what real files need (a 200k-triangle STL of 10 MB parses in
// ~0.3 s), far below what a hostile one could hold a core and a call for (a 945-byte PLY spins Assimp
// forever: tests/fuzz/regressions/mesh_ply_cpu_spin).
int ParseSecondsFor(size_t file_bytes) { return 10 + int(file_bytes >> 20); }

std::string ErrorAnswer(ErrorCode code, const std::string& message) {
  std::string out(1, '\1');
  out += static_cast<char>(code);
  out += message;
  return out;
}

// The child's limits: what a hostile file may cost it before it fails. Not under AddressSanitizer, whose
// shadow memory already reserves terabytes of address space.
void LimitChild(size_t file_bytes) {
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GRASPSIM_ASAN 1
#endif
#endif
#if !defined(__SANITIZE_ADDRESS__) && !defined(GRASPSIM_ASAN)
  const rlim_t address_space = (rlim_t{1} << 30) + 32 * static_cast<rlim_t>(file_bytes);
  const rlimit memory{address_space, address_space};
  setrlimit(RLIMIT_AS, &memory);
#endif
  const rlim_t seconds = rlim_t(ParseSecondsFor(file_bytes)) + 1;  // the server's deadline ends it first
  const rlimit cpu{seconds, seconds + 1};  // SIGXCPU at the soft limit
  setrlimit(RLIMIT_CPU, &cpu);
}

std::string SignalName(int signal_number) {
  const char* name = sigabbrev_np(signal_number);
  return name != nullptr ? std::string("SIG") + name : "signal " + std::to_string(signal_number);
}

}  // namespace

int ServeMeshImport(int in_fd, int out_fd) {
  std::string request;
  ReadAll(in_fd, &request);
  Reader reader{request};
  char magic[4];
  std::string_view field, path, bytes;
  Vec3 scale;
  uint64_t max_triangles = 0;
  if (!reader.Bytes(magic, 4) || std::memcmp(magic, kMagic, 4) != 0 || !reader.Text(&field) || !reader.Text(&path) ||
      !reader.Get(&scale.x()) || !reader.Get(&scale.y()) || !reader.Get(&scale.z()) || !reader.Get(&max_triangles) ||
      !reader.Text(&bytes)) {
    WriteAll(out_fd, ErrorAnswer(ErrorCode::kInternal, "graspsim-mesh-import: a malformed request"));
    return 2;
  }
  LimitChild(bytes.size());
  std::string answer;
  try {
    Limits limits;
    limits.max_triangles_per_mesh = max_triangles;
    const TriangleMesh mesh = ImportMeshInProcess(std::string(field), std::string(path), bytes, scale, limits);
    answer.assign(1, '\0');
    Put<uint64_t>(&answer, mesh.vertices.size());
    Put<uint64_t>(&answer, mesh.triangles.size());
    PutBytes(&answer, mesh.vertices.data(), mesh.vertices.size() * sizeof(mesh.vertices[0]));
    PutBytes(&answer, mesh.triangles.data(), mesh.triangles.size() * sizeof(mesh.triangles[0]));
  } catch (const Error& error) {
    answer = ErrorAnswer(error.code(), error.what());
  } catch (const std::bad_alloc&) {
    answer = ErrorAnswer(ErrorCode::kResourceExhausted, std::string(field) + ": mesh file '" + std::string(path) +
                                                            "' needs more memory to parse than its size warrants");
  } catch (const std::exception& error) {
    answer = ErrorAnswer(ErrorCode::kInvalidArgument, std::string(field) + ": mesh file '" + std::string(path) +
                                                          "' does not parse: " + error.what());
  }
  return WriteAll(out_fd, answer) ? 0 : 1;
}

std::string MeshImporterPath() {
  if (const char* path = std::getenv("GRASPSIM_MESH_IMPORT"); path != nullptr && *path != '\0') return path;
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  return (error ? std::filesystem::path(".") : self.parent_path()) / "graspsim-mesh-import";
}

namespace {

TriangleMesh ParseInChild(const std::string& field, const std::string& path, std::string_view bytes,
                          const Vec3& scale, const Limits& limits) {
  const std::string importer = MeshImporterPath();
  const std::string where = field + ": mesh file '" + path + "'";
  if (access(importer.c_str(), X_OK) != 0) {
    throw Error(ErrorCode::kFailedPrecondition, where + ": the mesh parser '" + importer +
                                                    "' is missing (it is built beside graspsim-server; or set "
                                                    "GRASPSIM_MESH_IMPORT)");
  }
  std::string request(kMagic, 4);
  PutText(&request, field);
  PutText(&request, path);
  Put(&request, scale.x());
  Put(&request, scale.y());
  Put(&request, scale.z());
  Put<uint64_t>(&request, limits.max_triangles_per_mesh);
  PutText(&request, bytes);

  int sockets[2];
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sockets) != 0) {
    throw Error(ErrorCode::kInternal, where + ": socketpair: " + std::strerror(errno));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, sockets[1], 0);  // dup2 clears close-on-exec on 0 and 1
  posix_spawn_file_actions_adddup2(&actions, sockets[1], 1);
  char* argv[] = {const_cast<char*>(importer.c_str()), nullptr};
  pid_t child = 0;
  const int spawned = posix_spawn(&child, importer.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  close(sockets[1]);
  if (spawned != 0) {
    close(sockets[0]);
    throw Error(ErrorCode::kInternal, where + ": cannot start '" + importer + "': " + std::strerror(spawned));
  }
  const int seconds = ParseSecondsFor(bytes.size());
  WriteAll(sockets[0], request);  // a child that died early is found below
  shutdown(sockets[0], SHUT_WR);
  std::string answer;
  const bool in_time = ReadAll(sockets[0], &answer, std::chrono::steady_clock::now() + std::chrono::seconds(seconds));
  close(sockets[0]);
  if (!in_time) kill(child, SIGKILL);
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (!in_time) {
    ThrowInvalidArgument(where + " could not be parsed: the parser took more than " + std::to_string(seconds) +
                         " s on it (the limit for its size)");
  }
  if (WIFSIGNALED(status)) {
    const int signal_number = WTERMSIG(status);
    ThrowInvalidArgument(where + " could not be parsed: the parser " +
                         (signal_number == SIGXCPU ? "ran out of its " + std::to_string(seconds) + " s of CPU time"
                                                   : "crashed on it (" + SignalName(signal_number) + ")"));
  }

  Reader reader{answer};
  char kind = 0;
  if (!reader.Get(&kind)) ThrowInvalidArgument(where + " could not be parsed: the parser ended without an answer");
  if (kind == '\1') {
    uint8_t code = 0;
    reader.Get(&code);
    const ErrorCode error = code <= static_cast<uint8_t>(ErrorCode::kInternal) ? static_cast<ErrorCode>(code)
                                                                              : ErrorCode::kInternal;
    throw Error(error, std::string(reader.data));
  }
  uint64_t vertices = 0, triangles = 0;
  TriangleMesh mesh;
  if (!reader.Get(&vertices) || !reader.Get(&triangles) || vertices > reader.data.size() / sizeof(mesh.vertices[0]) ||
      triangles > reader.data.size() / sizeof(mesh.triangles[0])) {
    throw Error(ErrorCode::kInternal, where + ": the parser's answer is truncated");
  }
  mesh.vertices.resize(vertices);
  mesh.triangles.resize(triangles);
  if (!reader.Bytes(mesh.vertices.data(), vertices * sizeof(mesh.vertices[0])) ||
      !reader.Bytes(mesh.triangles.data(), triangles * sizeof(mesh.triangles[0]))) {
    throw Error(ErrorCode::kInternal, where + ": the parser's answer is truncated");
  }
  ValidateMesh(mesh, where, limits.max_triangles_per_mesh);  // trust nothing that crossed a process boundary
  return mesh;
}

}  // namespace

std::shared_ptr<const TriangleMesh> LoadSharedMeshFile(const std::string& field, const std::string& path,
                                                       std::string_view bytes, const Vec3& scale, const Limits& limits) {
  CheckMeshFileRequest(field, path, bytes, scale);
  ParsedMeshCache& cache = ParsedMeshCache::Instance();
  const std::string key = ParsedMeshCache::Key(path, bytes, scale, limits.max_triangles_per_mesh);
  if (auto parsed = cache.Find(key)) return parsed;
  auto mesh = std::make_shared<const TriangleMesh>(ParseInChild(field, path, bytes, scale, limits));
  cache.Put(key, mesh);
  return mesh;
}

TriangleMesh LoadMeshFile(const std::string& field, const std::string& path, std::string_view bytes,
                          const Vec3& scale, const Limits& limits) {
  return *LoadSharedMeshFile(field, path, bytes, scale, limits);
}

}  // namespace graspsim
