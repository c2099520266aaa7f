#include "grasp/store.h"

#include <sqlite3.h>

#include <algorithm>
#include <cstring>
#include <sstream>

#include "core/bytes.h"
#include "core/error.h"
#include "core/sha256.h"
#include "core/sqlite_file.h"

namespace graspsim::grasp {
namespace {

// Bumped when the blob layout changes; rows of another format are treated as absent and replaced.
constexpr int kFormat = 1;

constexpr char kLabel[] = "grasp store ";

[[noreturn]] void ThrowStore(const std::string& path, const std::string& what) { ThrowStoreError(kLabel, path, what); }

std::string Join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : "\n") + name;
  return out;
}

std::vector<std::string> Split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::string Pack(const GraspSet& set) {
  ByteWriter w;
  w.Put<uint64_t>(set.grasps.size());
  for (const PlannedGrasp& g : set.grasps) {
    w.Put<uint32_t>(g.candidate_index);
    w.Put(g.candidate.approach);
    w.Put(g.candidate.target);
    w.Put(g.candidate.reference);
    w.Put(g.candidate.roll);
    w.Put(g.candidate.standoff);
    w.Put<uint32_t>(g.candidate.preshape);
    w.Put(g.hand_pose.position);
    w.Put(g.hand_pose.orientation.w());
    w.Put(g.hand_pose.orientation.x());
    w.Put(g.hand_pose.orientation.y());
    w.Put(g.hand_pose.orientation.z());
    w.Put<uint32_t>(static_cast<uint32_t>(g.joints.size()));
    for (double q : g.joints) w.Put(q);
    w.Put(g.quality.epsilon);
    w.Put(g.quality.volume);
    w.Put<uint8_t>(g.quality.force_closure);
    w.Put<uint32_t>(static_cast<uint32_t>(g.contacts.size()));
    for (const GraspContact& c : g.contacts) {
      w.Put(c.point);
      w.Put(c.normal);
      w.Put<int32_t>(c.link);
    }
  }
  return w.bytes();
}

std::vector<PlannedGrasp> Unpack(const void* data, size_t size) {
  ByteReader r(data, size, "grasp store: a grasp set");
  std::vector<PlannedGrasp> grasps(r.Get<uint64_t>());
  for (PlannedGrasp& g : grasps) {
    g.candidate_index = r.Get<uint32_t>();
    g.candidate.approach = r.GetVec3();
    g.candidate.target = r.GetVec3();
    g.candidate.reference = r.GetVec3();
    g.candidate.roll = r.Get<double>();
    g.candidate.standoff = r.Get<double>();
    g.candidate.preshape = r.Get<uint32_t>();
    g.hand_pose.position = r.GetVec3();
    const double qw = r.Get<double>(), qx = r.Get<double>(), qy = r.Get<double>(), qz = r.Get<double>();
    g.hand_pose.orientation = Quat(qw, qx, qy, qz);
    g.joints.resize(r.Get<uint32_t>());
    for (double& q : g.joints) q = r.Get<double>();
    g.quality.epsilon = r.Get<double>();
    g.quality.volume = r.Get<double>();
    g.quality.force_closure = r.Get<uint8_t>() != 0;
    g.contacts.resize(r.Get<uint32_t>());
    for (GraspContact& c : g.contacts) {
      c.point = r.GetVec3();
      c.normal = r.GetVec3();
      c.link = r.Get<int32_t>();
    }
  }
  return grasps;
}

// A double as exact text (hex float), so that two parameters never share a key through rounding.
std::string Exact(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%a", value);
  return buffer;
}

// Runs a statement with no result rows; throws naming the statement's purpose.
struct Statement {
  sqlite3_stmt* stmt = nullptr;
  ~Statement() { sqlite3_finalize(stmt); }
};

}  // namespace

std::string MeshHash(const TriangleMesh& mesh) {
  std::string bytes;
  bytes.resize(mesh.vertices.size() * 12 + mesh.triangles.size() * 12);
  char* out = bytes.data();
  for (const auto& v : mesh.vertices) {
    std::memcpy(out, v.data(), 12);
    out += 12;
  }
  for (const auto& t : mesh.triangles) {
    std::memcpy(out, t.data(), 12);
    out += 12;
  }
  return Sha256Hex(bytes);
}

GraspSetKey MakeGraspSetKey(const std::string& hand, const std::string& mesh_hash,
                            const std::vector<ObstacleBox>& obstacles, const CandidateParams& c,
                            const ClosingParams& s, size_t max_grasps) {
  std::ostringstream text;
  text << "format=" << kFormat << "\nhand=" << hand << "\nhand_urdf_sha256=" << Sha256Hex(HandUrdf(hand))
       << "\nmesh_sha256=" << mesh_hash << "\nmethod=" << CandidateMethodName(c.method)
       << "\nspacing=" << Exact(c.spacing) << "\npadding=" << Exact(c.padding)
       << "\ncircle_samples=" << c.circle_samples << "\nrolls=" << c.rolls << "\nseed=" << c.seed
       << "\nmax_candidates=" << c.max_candidates << "\nmax_grasps=" << max_grasps << "\npreshapes=";
  for (uint32_t p : c.preshapes) text << p << ",";
  text << "\nstandoffs=";
  for (double d : c.standoffs) text << Exact(d) << ",";
  if (c.grasp_points) {
    text << "\ngrasp_points=";
    for (const Vec3* p : {&c.grasp_points->first, &c.grasp_points->second}) {
      for (int k = 0; k < 3; ++k) text << Exact((*p)[k]) << ",";
    }
  }
  text << "\nfriction=" << Exact(s.friction) << "\ncone_edges=" << s.cone_edges
       << "\ncontact_tolerance=" << Exact(s.contact_tolerance) << "\nsample_spacing=" << Exact(s.sample_spacing)
       << "\ncontacts_per_link=" << s.contacts_per_link << "\nobstacles=";
  for (const ObstacleBox& o : obstacles) {
    for (int k = 0; k < 3; ++k) text << Exact(o.centre[k]) << "," << Exact(o.half[k]) << ",";
    for (int k = 0; k < 9; ++k) text << Exact(o.axes(k)) << ",";
    text << ";";
  }
  // Materials only when given, so that the keys of sets planned without them stay what they were.
  if (!s.object_material.empty() || !s.link_materials.empty() || !s.friction_pairs.empty()) {
    text << "\nobject_material=" << s.object_material << "\nlink_materials=";
    for (const auto& [link, material] : s.link_materials) text << link << ":" << material << ",";
    std::vector<std::string> pairs;
    for (const FrictionPair& p : s.friction_pairs) {
      const auto [x, y] = std::minmax(p.material_a, p.material_b);
      pairs.push_back(x + ":" + y + "=" + Exact(p.friction));
    }
    std::sort(pairs.begin(), pairs.end());
    text << "\nfriction_pairs=";
    for (const std::string& p : pairs) text << p << ",";
  }
  return {Sha256Hex(text.str()), text.str()};
}

GraspStore::GraspStore(const std::string& directory) {
  // FULL: an acknowledged set survives a power cut too (a client may hold its id for PickAndPlace). NORMAL lost
  // every set planned since the last checkpoint in tests/bench/power_cut.py; one fsync is nothing beside a plan.
  db_ = OpenStoreFile(kLabel, directory, "grasp_sets.sqlite", "FULL", &path_);
  try {
    ExecSql(db_, kLabel, path_,
         "CREATE TABLE IF NOT EXISTS grasp_sets ("
         " key TEXT PRIMARY KEY, format INTEGER NOT NULL, hand TEXT NOT NULL, mesh_sha256 TEXT NOT NULL,"
         " params TEXT NOT NULL, created_unix REAL NOT NULL, candidates INTEGER NOT NULL, missed INTEGER NOT NULL,"
         " collisions INTEGER NOT NULL, simulated INTEGER NOT NULL, force_closure INTEGER NOT NULL,"
         " seconds REAL NOT NULL, preshapes TEXT NOT NULL, links TEXT NOT NULL, joints TEXT NOT NULL,"
         " grasps BLOB NOT NULL)");
  } catch (...) {
    sqlite3_close(db_);
    throw;
  }
}

GraspStore::~GraspStore() { sqlite3_close(db_); }

std::optional<StoredGraspSet> GraspStore::Find(const std::string& key) const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s;
  if (sqlite3_prepare_v2(db_,
                         "SELECT hand, mesh_sha256, params, created_unix, candidates, missed, collisions, simulated,"
                         " force_closure, seconds, preshapes, links, joints, grasps FROM grasp_sets"
                         " WHERE key = ?1 AND format = ?2",
                         -1, &s.stmt, nullptr) != SQLITE_OK) {
    ThrowStore(path_, sqlite3_errmsg(db_));
  }
  sqlite3_bind_text(s.stmt, 1, key.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_int(s.stmt, 2, kFormat);
  const int step = sqlite3_step(s.stmt);
  if (step == SQLITE_DONE) return std::nullopt;
  if (step != SQLITE_ROW) ThrowStore(path_, sqlite3_errmsg(db_));
  auto text = [&](int column) {
    const auto* p = sqlite3_column_text(s.stmt, column);
    return std::string(p ? reinterpret_cast<const char*>(p) : "");
  };
  StoredGraspSet out;
  out.key = key;
  out.hand = text(0);
  out.mesh_hash = text(1);
  out.params_text = text(2);
  out.created_unix = sqlite3_column_double(s.stmt, 3);
  GraspSet& set = out.set;
  set.hand = out.hand;
  set.candidates = sqlite3_column_int64(s.stmt, 4);
  set.missed = sqlite3_column_int64(s.stmt, 5);
  set.collisions = sqlite3_column_int64(s.stmt, 6);
  set.simulated = sqlite3_column_int64(s.stmt, 7);
  set.force_closure = sqlite3_column_int64(s.stmt, 8);
  set.seconds = sqlite3_column_double(s.stmt, 9);
  set.preshape_names = Split(text(10));
  set.link_names = Split(text(11));
  set.joint_names = Split(text(12));
  set.grasps = Unpack(sqlite3_column_blob(s.stmt, 13), sqlite3_column_bytes(s.stmt, 13));
  return out;
}

void GraspStore::Put(const StoredGraspSet& stored) {
  const std::string blob = Pack(stored.set);
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s;
  if (sqlite3_prepare_v2(db_,
                         "INSERT OR REPLACE INTO grasp_sets (key, format, hand, mesh_sha256, params, created_unix,"
                         " candidates, missed, collisions, simulated, force_closure, seconds, preshapes, links,"
                         " joints, grasps) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16)",
                         -1, &s.stmt, nullptr) != SQLITE_OK) {
    ThrowStore(path_, sqlite3_errmsg(db_));
  }
  const GraspSet& set = stored.set;
  const std::string preshapes = Join(set.preshape_names), links = Join(set.link_names), joints = Join(set.joint_names);
  sqlite3_bind_text(s.stmt, 1, stored.key.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_int(s.stmt, 2, kFormat);
  sqlite3_bind_text(s.stmt, 3, stored.hand.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(s.stmt, 4, stored.mesh_hash.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(s.stmt, 5, stored.params_text.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_double(s.stmt, 6, stored.created_unix);
  sqlite3_bind_int64(s.stmt, 7, static_cast<sqlite3_int64>(set.candidates));
  sqlite3_bind_int64(s.stmt, 8, static_cast<sqlite3_int64>(set.missed));
  sqlite3_bind_int64(s.stmt, 9, static_cast<sqlite3_int64>(set.collisions));
  sqlite3_bind_int64(s.stmt, 10, static_cast<sqlite3_int64>(set.simulated));
  sqlite3_bind_int64(s.stmt, 11, static_cast<sqlite3_int64>(set.force_closure));
  sqlite3_bind_double(s.stmt, 12, set.seconds);
  sqlite3_bind_text(s.stmt, 13, preshapes.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(s.stmt, 14, links.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(s.stmt, 15, joints.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_blob(s.stmt, 16, blob.data(), static_cast<int>(blob.size()), SQLITE_TRANSIENT);
  if (sqlite3_step(s.stmt) != SQLITE_DONE) ThrowStore(path_, sqlite3_errmsg(db_));
}

}  // namespace graspsim::grasp
