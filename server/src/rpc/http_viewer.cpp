#include "rpc/http_viewer.h"

#include <unistd.h>

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <google/protobuf/util/json_util.h>
#include <httplib.h>

#include "core/error.h"
#include "core/log.h"
#include "graspsim/v1/grasp.grpc.pb.h"
#include "graspsim/v1/scene.grpc.pb.h"
#include "graspsim/v1/tactile.grpc.pb.h"
#include "rpc/call.h"
#include "rpc/event_feed.h"
#include "rpc/http_json.h"
#include "rpc/packed_arrays.h"

namespace graspsim::rpc {
namespace {

constexpr char kScenePattern[] = "([A-Za-z0-9_.-]+)";
constexpr double kDefaultPoseRateHz = 30, kDefaultTactileRateHz = 10, kDefaultStreamSeconds = 300;

std::string HtmlEscape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string MessageJson(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  std::string json;
  (void)google::protobuf::util::MessageToJsonString(message, &json, options);
  return json;
}

void ReplyError(const grpc::Status& status, httplib::Response& res) {
  res.status = HttpStatusFor(status.error_code());
  res.set_content(StatusJson(status), "application/json");
}

std::string SseEvent(const char* event, const std::string& json) {
  return std::string("event: ") + event + "\ndata: " + json + "\n\n";
}

// A query parameter as a positive number, or `fallback` when absent. Error(kInvalidArgument) naming it.
double PositiveParam(const httplib::Request& req, const std::string& name, double fallback) {
  if (!req.has_param(name)) return fallback;
  const std::string text = req.get_param_value(name);
  double value = NAN;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (result.ec != std::errc() || result.ptr != text.data() + text.size() || !std::isfinite(value) || value <= 0) {
    ThrowInvalidArgument(name + ": '" + text.substr(0, 40) + "' is not a positive number");
  }
  return value;
}

}  // namespace

std::string AuthorizationOf(const httplib::Request& req) {
  if (req.has_header("Authorization")) return req.get_header_value("Authorization");
  if (req.has_param("token")) return "Bearer " + req.get_param_value("token");
  // Cookie: a; graspsim_token=<token>; b
  const std::string cookies = req.get_header_value("Cookie");
  constexpr std::string_view kName = "graspsim_token=";
  for (size_t at = cookies.find(kName); at != std::string::npos; at = cookies.find(kName, at + 1)) {
    if (at != 0 && cookies[at - 1] != ' ' && cookies[at - 1] != ';') continue;
    const size_t begin = at + kName.size();
    return "Bearer " + cookies.substr(begin, cookies.find(';', begin) - begin);
  }
  return "";
}

void RememberToken(const httplib::Request& req, httplib::Response& res) {
  const std::string token = req.get_param_value("token");
  if (token.empty() || token.find_first_of(";, \r\n") != std::string::npos) return;
  res.set_header("Set-Cookie", "graspsim_token=" + token + "; Path=/; HttpOnly; SameSite=Strict" +
                                   (req.ssl != nullptr ? "; Secure" : ""));
}

namespace {

std::unique_ptr<grpc::ClientContext> ContextFor(const httplib::Request& req, double seconds) {
  auto context = std::make_unique<grpc::ClientContext>();
  if (const std::string authorization = AuthorizationOf(req); !authorization.empty()) {
    context->AddMetadata("authorization", authorization);
  }
  if (seconds > 0) {
    context->set_deadline(std::chrono::system_clock::now() +
                          std::chrono::duration_cast<std::chrono::system_clock::duration>(
                              std::chrono::duration<double>(seconds)));
  }
  return context;
}

// A gRPC server stream as the source of a feed. The call has no deadline: it lasts while viewers watch, and
// each viewer's own max_seconds ends only that viewer.
template <typename Message>
FeedSource StreamSource(const httplib::Request& req,
                        const std::function<std::unique_ptr<grpc::ClientReader<Message>>(grpc::ClientContext*)>& start,
                        std::function<void(const Message&, FeedEvent*)> encode) {
  struct Call {
    std::unique_ptr<grpc::ClientContext> context;
    std::unique_ptr<grpc::ClientReader<Message>> reader;
  };
  auto call = std::make_shared<Call>();
  call->context = ContextFor(req, 0);
  call->reader = start(call->context.get());
  return {[call, encode = std::move(encode)](FeedEvent* event) {
            Message message;
            if (!call->reader->Read(&message)) return false;
            encode(message, event);
            return true;
          },
          [call] { return call->reader->Finish(); },
          [call] { call->context->TryCancel(); }};
}

// Viewers share a feed only when they asked for the same stream with the same credentials.
std::string FeedKey(const std::string& stream, const httplib::Request& req, const std::string& options) {
  return stream + "\n" + std::string(req.matches[1]) + "\n" + options + "\n" + AuthorizationOf(req);
}

// Relays a feed to one browser as Server-Sent Events. The first event is awaited before answering, so a
// request that fails at once gets a plain error with its HTTP status.
void ServeFeed(std::unique_ptr<FeedTicket> ticket, double max_seconds, httplib::Response& res) {
  grpc::Status status;
  if (!ticket->feed().WaitFirst(&status)) return ReplyError(status, res);
  const auto until = EventFeed::Clock::now() + std::chrono::duration_cast<EventFeed::Clock::duration>(
                                                   std::chrono::duration<double>(max_seconds));
  res.set_header("Cache-Control", "no-cache");
  std::shared_ptr<FeedTicket> held(std::move(ticket));
  res.set_chunked_content_provider("text/event-stream", [held, until](size_t, httplib::DataSink& sink) {
    auto write = [&sink](const std::string& text) { return sink.write(text.data(), text.size()); };
    grpc::Status ended;
    if (!write("retry: 2000\n\n") || !held->feed().Serve(write, until, &ended)) return false;
    write(SseEvent("status", StatusJson(ended)));
    sink.done();
    return true;
  });
}

std::string Base64(const void* data, size_t size) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* bytes = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  for (size_t i = 0; i < size; i += 3) {
    const uint32_t chunk = (bytes[i] << 16) | (i + 1 < size ? bytes[i + 1] << 8 : 0) | (i + 2 < size ? bytes[i + 2] : 0);
    out += kDigits[(chunk >> 18) & 63];
    out += kDigits[(chunk >> 12) & 63];
    out += i + 1 < size ? kDigits[(chunk >> 6) & 63] : '=';
    out += i + 2 < size ? kDigits[chunk & 63] : '=';
  }
  return out;
}

// Contacts travel packed — float32 little-endian (6 per contact, 0.1 µm at 1 m) and uint32 pairs, base64 — as
// a held object has hundreds of contact points: formatting them as JSON numbers for every viewer cost the
// server more than the simulation (tests/bench/run viewers).
std::string ContactsJson(const v1::SceneSnapshot& snapshot) {
  const std::vector<double> values = Unpack<double>("contacts", snapshot.contacts());
  const std::string packed = Pack(std::vector<float>(values.begin(), values.end()));
  const std::string& bodies = snapshot.contact_bodies();
  return ",\"contacts_f32\":\"" + Base64(packed.data(), packed.size()) + "\",\"contact_bodies_u32\":\"" +
         Base64(bodies.data(), bodies.size()) + "\"";
}

// Per feed: the event names the body ids only when they changed since the feed's previous snapshot;
// `with_header` always names them, for viewers that have not seen this list yet (rpc/event_feed.h).
std::function<void(const v1::SceneSnapshot&, FeedEvent*)> SnapshotEncoder(bool contacts) {
  auto last_ids = std::make_shared<std::vector<std::string>>();
  auto epoch = std::make_shared<uint64_t>(0);
  return [last_ids, epoch, contacts](const v1::SceneSnapshot& snapshot, FeedEvent* event) {
    const std::string head = "{\"sequence\":" + std::to_string(snapshot.sequence()) +
                             ",\"revision\":" + std::to_string(snapshot.revision()) + ",\"time\":" + JsonNumber(snapshot.time());
    std::vector<std::string> ids(snapshot.body_ids().begin(), snapshot.body_ids().end());
    std::string ids_json = ",\"body_ids\":[";
    for (size_t i = 0; i < ids.size(); ++i) ids_json += (i ? "," : "") + JsonString(ids[i]);
    ids_json += "]";
    const bool changed = ids != *last_ids;
    if (changed) {
      *last_ids = std::move(ids);
      ++*epoch;
    }
    const std::vector<double> poses = Unpack<double>("body_poses", snapshot.body_poses());
    std::string body = ",\"poses\":[";
    for (size_t i = 0; i < poses.size(); ++i) body += (i ? "," : "") + JsonNumber(poses[i]);
    body += "]";
    if (contacts) body += ContactsJson(snapshot);
    body += "}";
    event->with_header = SseEvent("snapshot", head + ids_json + body);
    event->text = changed ? event->with_header : SseEvent("snapshot", head + body);
    event->header_epoch = *epoch;
  };
}

std::string TactileEvent(const v1::SensorReading& reading) {
  const v1::TactileReading& tactile = reading.tactile();
  std::string json = "{\"sensor_id\":" + JsonString(reading.sensor_id()) + ",\"time\":" + JsonNumber(reading.time()) +
                     ",\"rows\":" + std::to_string(tactile.rows()) + ",\"cols\":" + std::to_string(tactile.cols()) +
                     ",\"intensity_sum\":" + std::to_string(tactile.intensity_sum()) + ",\"intensities\":[";
  const std::vector<uint16_t> intensities = Unpack<uint16_t>("intensities", tactile.intensities());
  for (size_t i = 0; i < intensities.size(); ++i) json += (i ? "," : "") + std::to_string(intensities[i]);
  return SseEvent("reading", json + "]}");
}

std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class ViewerRoutes {
 public:
  ViewerRoutes(std::shared_ptr<grpc::Channel> channel, std::string dir, const SceneOverlays* overlays)
      : overlays_(overlays),
        scenes_(v1::SceneService::NewStub(channel)),
        tactile_(v1::TactileService::NewStub(channel)),
        grasps_(v1::GraspService::NewStub(channel)),
        dir_(std::move(dir)) {}

  static void Add(httplib::Server* server, const std::shared_ptr<ViewerRoutes>& self) {
    const std::string& dir_ = self->dir_;
    if (std::filesystem::exists(std::filesystem::path(dir_) / "index.html")) {
      server->set_mount_point("/view/assets", dir_);
    } else {
      Log(LogLevel::kWarn, "viewer files not found; /view pages answer 503", {{"viewer_dir", dir_}});
    }
    server->Get("/view/?", [self](const httplib::Request& req, httplib::Response& res) { self->SceneList(req, res); });
    const std::string scene = std::string("/view/") + kScenePattern;
    server->Get(scene, [self](const httplib::Request& req, httplib::Response& res) { self->Page(req, res); });
    server->Get(scene + "/scene.json", [self](const httplib::Request& req, httplib::Response& res) { self->SceneJson(req, res); });
    server->Get(scene + "/poses", [self](const httplib::Request& req, httplib::Response& res) { self->Guard(req, res, &ViewerRoutes::Poses); });
    server->Get(scene + "/tactile", [self](const httplib::Request& req, httplib::Response& res) { self->Guard(req, res, &ViewerRoutes::Tactile); });
    server->Get(scene + "/grasps", [self](const httplib::Request& req, httplib::Response& res) { self->Guard(req, res, &ViewerRoutes::Grasps); });
    server->Get(scene + "/overlays.json", [self](const httplib::Request& req, httplib::Response& res) { self->Overlays(req, res); });
  }

 private:
  using Handler = void (ViewerRoutes::*)(const httplib::Request&, httplib::Response&);
  void Guard(const httplib::Request& req, httplib::Response& res, Handler handler) {
    try {
      (this->*handler)(req, res);
    } catch (const Error& error) {
      ReplyError(ToStatus(error), res);
    }
  }

  grpc::Status GetScene(const httplib::Request& req, bool geometry, v1::Scene* scene) {
    v1::GetSceneRequest request;
    request.set_scene_id(req.matches[1]);
    request.set_include_geometry(geometry);
    return scenes_->GetScene(ContextFor(req, 30).get(), request, scene);
  }

  // The page itself is only the shell: everything else it fetches from the routes below.
  bool PageFile(const std::string& name, httplib::Response& res, std::string* text) {
    *text = ReadFile(std::filesystem::path(dir_) / name);
    if (!text->empty()) return true;
    res.status = 503;
    res.set_content("viewer files not found in '" + dir_ + "': build the graspsim-viewer target (make build)\n", "text/plain");
    return false;
  }

  void SceneList(const httplib::Request& req, httplib::Response& res) {
    v1::ListScenesResponse list;
    const grpc::Status status = scenes_->ListScenes(ContextFor(req, 30).get(), v1::ListScenesRequest(), &list);
    if (!status.ok()) return ReplyError(status, res);
    RememberToken(req, res);
    std::string rows;
    for (const auto& scene : list.scenes()) {
      const std::string id = HtmlEscape(scene.id());
      rows += "<tr><td><a href=\"/view/" + id + "\">" + id + "</a></td><td>" + HtmlEscape(scene.name()) + "</td><td>" +
              std::to_string(scene.body_count()) + "</td><td>" + std::to_string(scene.robot_count()) + "</td><td>" +
              JsonNumber(scene.time()) + "</td></tr>\n";
    }
    if (rows.empty()) rows = "<tr><td colspan=\"5\">no scenes yet: create one with SceneService.CreateScene</td></tr>\n";
    res.set_content("<!doctype html><html><head><meta charset=\"utf-8\"><title>graspsim scenes</title>"
                    "<link rel=\"stylesheet\" href=\"/view/assets/viewer.css\"></head><body class=\"list\">"
                    "<h1>graspsim scenes</h1><table id=\"scenes\"><tr><th>scene</th><th>name</th><th>bodies</th>"
                    "<th>robots</th><th>time (s)</th></tr>\n" + rows + "</table></body></html>\n",
                    "text/html; charset=utf-8");
  }

  void Page(const httplib::Request& req, httplib::Response& res) {
    v1::Scene scene;
    const grpc::Status status = GetScene(req, false, &scene);
    if (!status.ok()) return ReplyError(status, res);
    RememberToken(req, res);
    std::string page;
    if (PageFile("index.html", res, &page)) res.set_content(page, "text/html; charset=utf-8");
  }

  void SceneJson(const httplib::Request& req, httplib::Response& res) {
    v1::Scene scene;
    const grpc::Status status = GetScene(req, true, &scene);
    if (!status.ok()) return ReplyError(status, res);
    res.set_header("Cache-Control", "no-cache");
    res.set_content(MessageJson(scene), "application/json");
  }

  void Poses(const httplib::Request& req, httplib::Response& res) {
    const std::string contacts = req.get_param_value("contacts");
    if (!contacts.empty() && contacts != "0" && contacts != "1") {
      ThrowInvalidArgument("contacts: '" + contacts.substr(0, 40) + "'; give 1 (with contact points) or 0");
    }
    v1::WatchSceneRequest request;
    request.set_scene_id(req.matches[1]);
    request.set_max_rate_hz(PositiveParam(req, "max_rate_hz", kDefaultPoseRateHz));
    const double max_seconds = PositiveParam(req, "max_seconds", kDefaultStreamSeconds);
    auto ticket = feeds_.Join(FeedKey("poses", req, JsonNumber(request.max_rate_hz()) + (contacts == "1" ? "c" : "")), [&] {
      return StreamSource<v1::SceneSnapshot>(
          req, [&](grpc::ClientContext* context) { return scenes_->WatchScene(context, request); },
          SnapshotEncoder(contacts == "1"));
    });
    ServeFeed(std::move(ticket), max_seconds, res);
  }

  void Tactile(const httplib::Request& req, httplib::Response& res) {
    v1::Scene scene;
    const grpc::Status status = GetScene(req, false, &scene);
    if (!status.ok()) return ReplyError(status, res);
    if (scene.tactile_arrays().empty()) {
      return ReplyError(grpc::Status(grpc::StatusCode::NOT_FOUND,
                                     "scene '" + scene.summary().id() + "' has no tactile arrays"), res);
    }
    v1::StreamRequest request;
    request.set_scene_id(req.matches[1]);
    for (const auto& array : scene.tactile_arrays()) request.add_sensor_ids(array.id());
    request.set_rate_hz(PositiveParam(req, "rate_hz", kDefaultTactileRateHz));
    const double max_seconds = PositiveParam(req, "max_seconds", kDefaultStreamSeconds);
    auto ticket = feeds_.Join(FeedKey("tactile", req, JsonNumber(request.rate_hz())), [&] {
      return StreamSource<v1::SensorReading>(
          req, [&](grpc::ClientContext* context) { return tactile_->Stream(context, request); },
          [](const v1::SensorReading& reading, FeedEvent* event) {
            event->slot = reading.sensor_id();
            event->text = TactileEvent(reading);
          });
    });
    ServeFeed(std::move(ticket), max_seconds, res);
  }

  // Asks the scene first, so that the caller's credentials and the scene's existence are checked as for GetScene.
  void Overlays(const httplib::Request& req, httplib::Response& res) {
    v1::Scene scene;
    const grpc::Status status = GetScene(req, false, &scene);
    if (!status.ok()) return ReplyError(status, res);
    res.set_header("Cache-Control", "no-cache");
    res.set_content(overlays_ ? overlays_->Json(req.matches[1]) : SceneOverlays().Json(""), "application/json");
  }

  void Grasps(const httplib::Request& req, httplib::Response& res) {
    if (!req.has_param("set_id")) {
      return ReplyError(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                                     "set_id: missing; give the set_id PlanGrasps answered"), res);
    }
    v1::GetGraspSetRequest request;
    request.set_set_id(req.get_param_value("set_id"));
    v1::GraspSet set;
    const grpc::Status status = grasps_->GetGraspSet(ContextFor(req, 30).get(), request, &set);
    if (!status.ok()) return ReplyError(status, res);
    res.set_content(MessageJson(set), "application/json");
  }

  const SceneOverlays* overlays_;
  std::unique_ptr<v1::SceneService::Stub> scenes_;
  std::unique_ptr<v1::TactileService::Stub> tactile_;
  std::unique_ptr<v1::GraspService::Stub> grasps_;
  const std::string dir_;
  FeedRegistry feeds_;
};

}  // namespace

void AddViewerRoutes(httplib::Server* server, std::shared_ptr<grpc::Channel> channel, const std::string& viewer_dir,
                     const SceneOverlays* overlays) {
  ViewerRoutes::Add(server, std::make_shared<ViewerRoutes>(std::move(channel),
                                                           viewer_dir.empty() ? DefaultViewerDir() : viewer_dir, overlays));
}

std::string DefaultViewerDir() {
  std::error_code error;
  const std::filesystem::path binary = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return "share/graspsim/viewer";
  return (binary.parent_path().parent_path() / "share" / "graspsim" / "viewer").string();
}

}  // namespace graspsim::rpc
