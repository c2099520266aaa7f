// graspsim.v1.TactileService: sensor readings of a scene's state (sensors/sensor_registry.h) as messages, and the grasp
// work cycle (workcycle/work_cycle.h). Bodies run on the worker pool; Stream is a reactor per reader
// (sensor_stream.h), RunWorkCycle one per run (work_cycle_stream.h).
#pragma once

#include "core/worker_pool.h"
#include "physics/simulation_cache.h"
#include "graspsim/v1/tactile.grpc.pb.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

class TactileServiceImpl final : public v1::TactileService::CallbackService {
 public:
  // `max_rate_hz` caps Stream's rate_hz: the server's --watch-max-rate-hz, the limit of every stream.
  // `simulations` is the server's (shared with SceneService.StepSimulation), so both step a scene with the same
  // Simulation.
  TactileServiceImpl(SceneRegistry* registry, WorkerPool* pool, SimulationCache* simulations, double max_rate_hz)
      : registry_(registry), pool_(pool), simulations_(simulations), max_rate_hz_(max_rate_hz) {}

  using Context = grpc::CallbackServerContext;
  using Unary = grpc::ServerUnaryReactor;

  Unary* Sample(Context*, const v1::SampleRequest*, v1::SensorReading*) override;
  grpc::ServerWriteReactor<v1::SensorReading>* Stream(Context*, const v1::StreamRequest*) override;
  Unary* GetTactileImage(Context*, const v1::GetTactileImageRequest*, v1::TactileImage*) override;
  grpc::ServerWriteReactor<v1::WorkCycleProgress>* RunWorkCycle(Context*, const v1::RunWorkCycleRequest*) override;

 private:
  SceneRegistry* registry_;
  WorkerPool* pool_;
  SimulationCache* simulations_;
  const double max_rate_hz_;
};

}  // namespace graspsim::rpc
