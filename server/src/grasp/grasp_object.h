// Private to grasp/: the object to grasp, prepared once per planner: its mesh and Embree BVH (object frame),
// centroid, principal axes and characteristic length, its sharp vertices (which the closing simulation also
// sweeps against the hand, since sampling the hand's faces alone could let a corner slip between samples), and
// the obstacles around it (table, other bodies) as boxes in the object frame.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "collision/embree.h"
#include "core/math.h"
#include "core/mesh.h"
#include "grasp/hand_model.h"

namespace graspsim::grasp {

// An obstacle box in the object frame.
using ObstacleBox = LinkBox;

class GraspObject {
 public:
  // `mesh` must be validated (non-empty, finite, indices in range); obstacles are in the object frame.
  GraspObject(std::shared_ptr<const TriangleMesh> mesh, std::vector<ObstacleBox> obstacles);

  const TriangleMesh& mesh() const { return *mesh_; }
  const collision::EmbreeScene& bvh() const { return *bvh_; }
  const std::vector<Vec3>& face_normals() const { return face_normals_; }  // outward unit, per triangle
  const std::vector<Vec3>& sharp_vertices() const { return sharp_; }
  // The sharp vertices in small spatial clusters (a ball each, indices into sharp_vertices() ascending), so a
  // sweep tests a cluster before its members.
  struct VertexCluster {
    Vec3 centre = Vec3::Zero();
    double radius = 0;
    std::vector<uint32_t> members;
  };
  const std::vector<VertexCluster>& sharp_clusters() const { return clusters_; }
  const std::vector<ObstacleBox>& obstacles() const { return obstacles_; }
  Vec3 centroid() const { return centroid_; }            // of the surface (area-weighted), m
  const Mat3& principal_axes() const { return axes_; }   // columns: major, middle, minor
  double characteristic_length() const { return length_; }  // largest centroid-vertex distance, m
  Vec3 lo() const { return lo_; }
  Vec3 hi() const { return hi_; }

 private:
  void BuildClusters();

  std::shared_ptr<const TriangleMesh> mesh_;
  std::unique_ptr<collision::EmbreeScene> bvh_;
  std::vector<Vec3> face_normals_, sharp_;
  std::vector<ObstacleBox> obstacles_;
  std::vector<VertexCluster> clusters_;
  Vec3 centroid_ = Vec3::Zero(), lo_ = Vec3::Zero(), hi_ = Vec3::Zero();
  Mat3 axes_ = Mat3::Identity();
  double length_ = 0;
};

// Separating-axis test of two oriented boxes given in one frame (boxes touching within `margin` overlap).
bool BoxesOverlap(const LinkBox& a, const LinkBox& b, double margin);

}  // namespace graspsim::grasp
