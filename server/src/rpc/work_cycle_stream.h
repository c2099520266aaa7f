// TactileService.RunWorkCycle as a callback-API server stream: the work cycle runs on the worker pool in chunks
// under the scene's writers' lock (workcycle/scene_work_cycle.h), and its frames are written in order, every one.
//
// Flow control, not newest-wins: every frame is a sample of the run's time series, so none may be dropped.
// The simulation runs ahead of the writer by at most a small buffer of frames; when the buffer is full the
// next chunk is not scheduled until writes complete (a slow reader pauses the simulation, it never grows the
// memory). No thread ever waits: the pool runs one chunk per job, the writer's completion schedules the next.
#pragma once

#include <memory>

#include <grpcpp/grpcpp.h>

#include "core/worker_pool.h"
#include "graspsim/v1/tactile.pb.h"
#include "physics/simulation_cache.h"
#include "workcycle/work_cycle.h"
#include "world/scene.h"

namespace graspsim::rpc {

// Runs `request` on `scene`: the request is checked against the scene on the pool (an error ends the stream
// before anything is written), then one frame is written per 1/frame_rate_hz of simulated time and one as each
// stage begins, ending with the "done" frame and OK. A cycle error (something blocks the axis, the fingers close on nothing, the model
// changed) ends it with FAILED_PRECONDITION after the frames before it; the scene keeps the state of the last
// step. Ends with UNAVAILABLE when the scene is deleted or the server stops, CANCELLED when the reader
// cancels; the scene then keeps the state of the last chunk, its drives as the cycle left them.
// A write carries up to frames_per_message (1..kMaxFramesPerMessage) of the frames waiting, the first as the
// message and the rest in its `following`.
constexpr size_t kMaxFramesPerMessage = 64;
grpc::ServerWriteReactor<v1::WorkCycleProgress>* StartWorkCycleStream(std::shared_ptr<Scene> scene,
                                                                      WorkCycleRequest request,
                                                                      size_t frames_per_message,
                                                                      SimulationCache* simulations, WorkerPool* pool,
                                                                      grpc::CallbackServerContext* context);

}  // namespace graspsim::rpc
