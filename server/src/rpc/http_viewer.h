// The browser viewer's HTTP routes, beside the HTTP/JSON gateway on the same port. Read-only: every route
// reaches the services through the in-process gRPC channel (the same checks as any client) and only reads.
//
//   GET /view                      scene list page (links to each scene's viewer)
//   GET /view/assets/<file>        the bundled viewer (viewer/ in the source tree, built by graspsim-viewer)
//   GET /view/<scene>              the viewer page of a scene; 404 with a message for an unknown scene
//   GET /view/<scene>/scene.json   bodies, joints, tactile arrays with inline geometry (GetScene): fetched once
//                                  per viewer, again only when the snapshot's body list changes
//   GET /view/<scene>/poses        Server-Sent Events: "snapshot" {sequence, revision, time, poses[7 per body],
//                                  body_ids only when they changed on this connection; with contacts=1 also
//                                  contacts_f32 (base64 of float32 LE, 6 per contact: point m, force on the
//                                  first body N, world) and contact_bodies_u32 (base64 of uint32 LE pairs)},
//                                  from WatchScene — newest snapshot per viewer, at most max_rate_hz
//                                  (default 30) per second; viewers asking the same share one encoding
//                                  (rpc/event_feed.h)
//   GET /view/<scene>/tactile      Server-Sent Events: "reading" {sensor_id, time, rows, cols, intensities,
//                                  intensity_sum} of every tactile array, from TactileService.Stream (rate_hz, 10)
//   GET /view/<scene>/grasps?set_id=<id>   a stored grasp set (GetGraspSet), best ε first
//   GET /view/<scene>/overlays.json         rpc/scene_overlays.h: the symmetry plane of the last completion added
//                                           to the scene and the tip path of the last PlanArmPath in it
// An event stream ends with "event: status" {code, status, message}; streams end on their own after
// max_seconds (default 300) so that a browser gone quiet on an idle scene frees its thread; EventSource
// reconnects by itself.
#pragma once

#include <memory>
#include <string>

#include <grpcpp/grpcpp.h>

#include "rpc/scene_overlays.h"

namespace httplib {
class Server;
struct Request;
struct Response;
}

namespace graspsim::rpc {

// Adds the routes. `viewer_dir` holds index.html, viewer.js, viewer.css; empty = DefaultViewerDir(). A
// missing directory is logged and the pages answer 503 naming it; the event and JSON routes still work.
// `overlays` may be null (overlays.json then reports none).
void AddViewerRoutes(httplib::Server* server, std::shared_ptr<grpc::Channel> channel, const std::string& viewer_dir,
                     const SceneOverlays* overlays = nullptr);

// The caller's credentials as an authorization metadata value ("Bearer <token>"): the Authorization header, else
// a ?token= query parameter (a link that opens the viewer), else the graspsim_token cookie that such a link sets.
// Empty when there are none. The interceptor checks them (rpc/auth_interceptor.h), as for any gRPC client.
std::string AuthorizationOf(const httplib::Request& req);
// A ?token= query parameter becomes an HttpOnly, SameSite=Strict cookie, so the page's own fetches carry it.
void RememberToken(const httplib::Request& req, httplib::Response& res);

// <directory of the running binary>/../share/graspsim/viewer: where the build and an install put the files.
std::string DefaultViewerDir();

}  // namespace graspsim::rpc
