// One scene: its model, its state, its uploaded files and its watchers. Every edit is validated against a copy
// and swapped in whole, so a rejected edit changes nothing. Two locks: writers take write_mutex_, which orders
// them and is held from validation through the journal write (and a simulation chunk) to the swap; the swap
// itself and every reader take mutex_, held only as long as a copy or a short read. So a reader never waits
// for the journal's fsync or for physics, and still sees only what is stored. Slow work (parsing URDF and
// meshes) happens before the edit, outside both, so it never blocks other requests.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "core/limits.h"
#include "world/loaders.h"
#include "world/model.h"
#include "world/scene_journal.h"
#include "world/snapshot_hub.h"
#include "world/state.h"

namespace graspsim {

struct StoredFile {
  std::shared_ptr<const std::string> bytes;
  std::string sha256;
};

// A consistent copy of everything a reader needs, taken under the lock.
struct SceneView {
  std::string id, name;
  uint64_t revision = 0;
  std::shared_ptr<const SceneModel> model;
  SceneState state;
  std::map<std::string, StoredFile> files;
};

struct AddedRobot {
  RobotSpec robot;
  std::vector<BodySpec> bodies;
  std::vector<JointSpec> joints;
  std::vector<TactileArraySpec> tactile_arrays;
};

class Scene {
 public:
  Scene(std::string id, std::string name, const Limits& limits);

  const std::string& id() const { return id_; }
  SceneView View() const;
  // A short read in place, under the readers' lock: `read` sees the model, the state and the revision without
  // the copy a View makes (the state's contacts, bristles and pad forces are hundreds of entries while a hand
  // holds something). `read` must be quick and must not call back into the scene; what it throws propagates.
  using ReadFn = std::function<void(const SceneModel& model, const SceneState& state, uint64_t revision)>;
  void Read(const ReadFn& read) const;
  // The same without waiting: false (and `read` not called) while another reader or a writer's swap holds the
  // readers' lock. For short reads answered on gRPC's own threads, which must never wait.
  bool TryRead(const ReadFn& read) const;
  uint64_t revision() const;
  SnapshotHub& snapshots() { return hub_; }

  // Edits with a SceneOp are journaled with it (world/scene_journal.h); an edit whose journal write fails is
  // dropped and throws. Without a journal (tests, replay on start, --data-dir=off) the op is ignored.
  // Stores every later edit in `journal` (it outlives the scene); set once the scene was rebuilt on start.
  void AttachJournal(SceneJournal* journal);
  // Replay on start: the stored state and revision of a scene whose model was rebuilt from its log. Throws
  // Error(kInternal) when the state does not fit the model (a log and a state that disagree).
  void RestoreState(SceneState state, uint64_t revision);
  // Journals the state as it is now if it changed since the last journal write (simulation runs commit their
  // chunks with journal = false and call this at the end of a request and every second of a long run).
  void Checkpoint();

  // Files: stored whole after the caller checked size and checksum; replaces a file of the same path.
  void PutFile(const std::string& path, std::shared_ptr<const std::string> bytes, const std::string& sha256,
               const SceneOp* op = nullptr);
  // The scene's files as they are now, for a loader running outside the lock.
  std::map<std::string, StoredFile> Files() const;

  // `body.id` is the object's name; motion kStatic or kFree. Errors: kAlreadyExists, kResourceExhausted.
  BodySpec AddObject(BodySpec body, const Pose& pose, const SceneOp* op = nullptr);
  // Places a loaded description under `name`: ids become "<name>/<urdf name>".
  AddedRobot AddRobot(const std::string& name, const std::string& source, const RobotDescription& description,
                      const Pose& base_pose, const SceneOp* op = nullptr);
  // Removes an object or a whole robot; returns the removed body ids.
  std::vector<std::string> Remove(const std::string& id, const SceneOp* op = nullptr);

  // All or nothing. Ids: objects, robots (their base), robots' base bodies. Velocities (of the centre of mass
  // and about it, world) only for free objects. A body moved or set moving wakes.
  uint64_t SetBodyPoses(const std::vector<std::pair<std::string, Pose>>& poses,
                        const std::vector<std::pair<std::string, BodyVelocity>>& velocities = {});
  // All or nothing; limits checked; mimic joints follow their leader (setting a follower is an error), in
  // position and in velocity (rad/s or m/s).
  uint64_t SetJointPositions(const std::vector<std::pair<std::string, double>>& positions,
                             const std::vector<std::pair<std::string, double>>& velocities = {});

  // Runs `change` on the model and a copy of the state under the writers' lock (readers meanwhile see the state
  // before it); commits the copy (revision, snapshot) when it returns, keeps the old state when it throws. For
  // the simulation, which lives above world.
  using StateChange = std::function<void(const std::shared_ptr<const SceneModel>& model, SceneState* state)>;
  // `journal` false: the change is journaled by a later Checkpoint (simulation chunks), not now.
  uint64_t Update(const StateChange& change, bool journal = true);
  // From inside an Update's change only (it holds the writers' lock): publishes `state`, not yet committed, as a
  // frame to the watchers that want detail (recordings, live feeds), so that a long update that runs many
  // chunks (the work cycle) is recorded chunk by chunk. Nothing when no watcher wants detail.
  void PublishDuringUpdate(const SceneState& state);
  // A new model with these simulation parameters (validated by the caller).
  uint64_t SetSimulationParams(const SimulationParams& params, const SceneOp* op = nullptr);

  // A snapshot of the scene as it is now, with its model, state and edits (SceneSnapshot::model, ::state, ::edits).
  std::shared_ptr<const SceneSnapshot> DetailedSnapshot() const;

  // Ends every watcher's stream (scene deleted or server stopping).
  void CloseWatchers(const std::string& reason) { hub_.Close(reason); }

 private:
  // Caller holds write_mutex_. Writes the edit (op, the state after it) to the journal before it is swapped in;
  // throws when the journal cannot, and then the caller has changed nothing yet.
  void Journal(const SceneOp* op, const SceneState& state, bool changes_model = false);
  // Caller holds both locks. Records op among the edits, bumps the revision and publishes a snapshot.
  void CommitLocked(const SceneOp* op);
  void AppendEditLocked(const SceneOp* op);
  void PublishLocked();
  // Caller holds mutex_ (the id lists it caches are shared by readers and writers).
  std::shared_ptr<SceneSnapshot> SnapshotLocked(const SceneState& state, uint64_t revision, bool detail,
                                               bool publish) const;
  // Caller holds write_mutex_.
  size_t BodyIndex(const std::string& id) const;
  size_t JointIndex(const std::string& id) const;
  void CheckIdFree(const std::string& field, const std::string& id) const;

  const std::string id_, name_;
  const Limits limits_;
  std::mutex write_mutex_;     // orders the writers (see the class comment); taken before mutex_
  mutable std::mutex mutex_;  // the readers' lock: what they read changes only under it
  std::shared_ptr<const SceneModel> model_;
  SceneState state_;
  std::map<std::string, StoredFile> files_;
  uint64_t file_bytes_ = 0;
  uint64_t revision_ = 0;
  SceneJournal* journal_ = nullptr;
  uint64_t journaled_revision_ = 0;  // the revision whose state the journal holds
  // Every model edit with its op, in order, kept with or without a journal (recordings replay them). Replaced,
  // never changed in place, so snapshots share it.
  std::shared_ptr<const SceneEdits> edits_ = std::make_shared<const SceneEdits>();
  mutable uint64_t snapshot_sequence_ = 0;
  double last_detail_time_ = -1;  // simulated time of the last detailed snapshot published
  mutable std::shared_ptr<const std::vector<std::string>> snapshot_body_ids_, snapshot_joint_ids_;
  mutable std::shared_ptr<const SceneModel> snapshot_ids_model_;  // the model the id lists were built from
  SnapshotHub hub_;
};

}  // namespace graspsim
