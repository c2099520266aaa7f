// PCL lives here only (DESIGN.md: heavy headers, never in a public header).
#include "perception/segmentation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <pcl/ModelCoefficients.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/sac_segmentation.h>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"

namespace graspsim {
namespace {

void CheckRange(const std::string& field, double value, double lo, double hi) {
  CheckFinite(field, value);
  if (!(value > lo) || value > hi) {
    ThrowInvalidArgument(field + ": " + FormatNumber(value) + " is outside (" + FormatNumber(lo) + ", " +
                         FormatNumber(hi) + "]");
  }
}

}  // namespace

SceneSegmentation SegmentScene(const std::vector<Vec3>& points, const SegmentationParams& params) {
  CheckRange("plane_threshold", params.plane_threshold, 0, 1);
  CheckRange("cluster_tolerance", params.cluster_tolerance, 0, 1);
  if (params.min_cluster_points < 1) {
    ThrowInvalidArgument("min_cluster_points: " + std::to_string(params.min_cluster_points) + " must be ≥ 1");
  }
  if (params.ransac_iterations < 1 || params.ransac_iterations > 100000) {
    ThrowInvalidArgument("ransac_iterations: " + std::to_string(params.ransac_iterations) + " is outside 1..100000");
  }
  if (points.empty()) ThrowInvalidArgument("cloud.points: the cloud is empty");
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    CheckFinite("cloud.points[" + std::to_string(i) + "]", points[i]);
    cloud->push_back(pcl::PointXYZ(float(points[i].x()), float(points[i].y()), float(points[i].z())));
  }

  // The table: RANSAC's best plane. PCL's SAC draws from std::rand, seeded here so the answer repeats.
  std::srand(12345);
  pcl::SACSegmentation<pcl::PointXYZ> ransac;
  ransac.setOptimizeCoefficients(true);
  ransac.setModelType(pcl::SACMODEL_PLANE);
  ransac.setMethodType(pcl::SAC_RANSAC);
  ransac.setDistanceThreshold(params.plane_threshold);
  ransac.setMaxIterations(params.ransac_iterations);
  ransac.setInputCloud(cloud);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients plane;
  ransac.segment(inliers, plane);
  if (inliers.indices.size() < 3 || plane.values.size() != 4) {
    ThrowInvalidArgument("cloud.points: no plane found in " + std::to_string(points.size()) +
                         " points (fewer than 3, or all on a line)");
  }
  Vec3 normal(plane.values[0], plane.values[1], plane.values[2]);
  double offset = -plane.values[3];
  const double length = normal.norm();
  normal /= length;
  offset /= length;

  // Up is the side most of the other points are on (a table-top scene's objects stand on the table).
  std::vector<char> is_table(points.size(), 0);
  for (int i : inliers.indices) is_table[size_t(i)] = 1;
  size_t above = 0, below = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (is_table[i]) continue;
    (normal.dot(points[i]) > offset ? above : below) += 1;
  }
  if (below > above || (below == above && normal.z() < 0)) {
    normal = -normal;
    offset = -offset;
  }

  SceneSegmentation out;
  out.table_normal = normal;
  out.table_offset = offset;
  out.table_points = inliers.indices.size();
  pcl::PointCloud<pcl::PointXYZ>::Ptr objects(new pcl::PointCloud<pcl::PointXYZ>);
  std::vector<size_t> source;
  for (size_t i = 0; i < points.size(); ++i) {
    if (is_table[i] || normal.dot(points[i]) - offset <= params.plane_threshold) continue;
    objects->push_back((*cloud)[i]);
    source.push_back(i);
  }
  if (objects->empty()) return out;
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(objects);
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> clustering;
  clustering.setClusterTolerance(params.cluster_tolerance);
  clustering.setMinClusterSize(params.min_cluster_points);
  clustering.setMaxClusterSize(std::numeric_limits<int>::max());
  clustering.setSearchMethod(tree);
  clustering.setInputCloud(objects);
  std::vector<pcl::PointIndices> clusters;
  clustering.extract(clusters);  // largest first
  for (auto& cluster : clusters) {
    std::sort(cluster.indices.begin(), cluster.indices.end());  // input order within an object
    auto& object = out.objects.emplace_back();
    object.reserve(cluster.indices.size());
    for (int i : cluster.indices) object.push_back(points[source[size_t(i)]]);
  }
  return out;
}

}  // namespace graspsim
