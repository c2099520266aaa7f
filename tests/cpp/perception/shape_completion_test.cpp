// Shape completion end to end in process (perception/shape_completion.h): views rendered by exact ray casts
// (render_view.h) of solids standing on a table, 320 × 240 pixels, f = 300 px, the camera 0.5–0.6 m away and
// 30–35° above the table. Tolerances (figures measured when set are printed by each test):
//   - symmetry plane within 2° and 2 mm of the solid's true mid-plane (the bound), with 3 refinement
//     passes after the paper's 7 × 5 grid;
//   - completion of a cylinder seen from one side: mean two-sided deviation from the true surface < 1 mm (the
//     issue's bound; the table side is never seen and is closed by Poisson);
//   - the same input twice gives the same mesh bit for bit.
#include <cmath>
#include <cstring>
#include <functional>
#include <iostream>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"
#include "perception/cloud_filters.h"
#include "perception/delaunay_baseline.h"
#include "perception/free_space.h"
#include "perception/mesh_metrics.h"
#include "perception/render_view.h"
#include "perception/shape_completion.h"
#include "perception/shapes.h"
#include "perception/mesh_deviation.h"

namespace graspsim {
namespace {

using test_shapes::Deviation;
using test_shapes::Measure;

constexpr double kDeg = M_PI / 180;

// 320 × 240, f = 300 px; scale 2: 640 × 480, f = 600 px (a Kinect-class camera).
CameraIntrinsics Camera(int scale = 1) {
  CameraIntrinsics k;
  k.width = 320 * scale;
  k.height = 240 * scale;
  k.fx = k.fy = 300 * scale;
  k.cx = 0.5 * (k.width - 1);
  k.cy = 0.5 * (k.height - 1);
  return k;
}

// An eye `distance` from `target`, `azimuth` about z from +x, `elevation` above the table.
Pose EyeAt(const Vec3& target, double distance, double azimuth, double elevation) {
  const Vec3 eye = target + distance * Vec3(std::cos(elevation) * std::cos(azimuth),
                                            std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  return test_render::LookAt(eye, target);
}

// Bohg et al.'s mesh deviation against an upright capped cylinder standing on the table, centred at `centre`.
Deviation CylinderDeviation(const TriangleMesh& mesh, double r, double h, const Vec3& centre) {
  test_shapes::OrientedCloud truth = test_shapes::Cylinder(r, h, 0.002);
  for (Vec3& p : truth.points) p += centre;
  return Measure(mesh, [&](const Vec3& p) { return test_shapes::CylinderDistance(p - centre, r, h); }, truth.points);
}

// Distance from a point to the plane, and angle between the plane's normal and an axis (either sign).
double PlaneDistance(const SymmetryPlane& plane, const Vec3& p) { return std::abs((p - plane.point).dot(plane.normal)); }
double AxisAngleDeg(const Vec3& a, const Vec3& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) / kDeg;
}


struct BoxScene {
  Vec3 size{0.08, 0.12, 0.10};
  Pose pose;
  Pose camera;
  PartialView view;
};

// A box 8 × 12 × 10 cm standing on the table, turned 10° about z, seen along (about) its short axis.
BoxScene MakeBoxScene(double noise_sigma = 0) {
  BoxScene s;
  s.pose.position = Vec3(0.01, -0.02, 0.05);
  s.pose.orientation = Quat(Eigen::AngleAxisd(10 * kDeg, Vec3::UnitZ()));
  s.camera = EyeAt(s.pose.position, 0.55, 200 * kDeg, 35 * kDeg);
  std::mt19937 random(3);
  std::normal_distribution<double> gauss(0, noise_sigma > 0 ? noise_sigma : 1);
  s.view.image = test_render::Render(test_render::Box(s.size, s.pose), s.camera, Camera(),
                                     [&](int, int) { return noise_sigma > 0 ? gauss(random) : 0.0; });
  s.view.camera_pose = s.camera;
  return s;
}

CompletionOptions Refined(int depth = 6) {
  CompletionOptions options;
  options.symmetry.refinements = 4;
  options.poisson.depth = depth;
  return options;
}

TEST(ShapeCompletionTest, MirrorRecoversTheBoxsMidPlane) {
  for (double sigma : {0.0, 0.001}) {
    const BoxScene s = MakeBoxScene(sigma);
    const auto result = CompleteShape(s.view, Refined());
    ASSERT_TRUE(result && result->plane);
    const SymmetryPlane& plane = *result->plane;
    // Seen from 200° the view runs along the box's local x axis: that mid-plane is the one to find.
    const Vec3 truth = s.pose.orientation * Vec3::UnitX();
    const double angle = AxisAngleDeg(plane.normal, truth), offset = PlaneDistance(plane, s.pose.position);
    std::cout << "noise " << sigma * 1e3 << " mm: angle " << angle << " deg, offset " << offset * 1e3
              << " mm, score " << plane.score << ", " << plane.hypotheses << " hypotheses\n";
    EXPECT_LT(angle, 2.0);
    EXPECT_LT(offset, 0.002);
    EXPECT_LT(std::abs(plane.normal.z()), 1e-12);  // perpendicular to the table
  }
}

// The defaults the service uses: a cloud above target_points is voxel down-sampled to about that many points, one
// below is left alone; and scoring on a subset of score_points picks the plane all points pick.
TEST(ShapeCompletionTest, LargeCloudsAreDownSampledToTheTargetAndTheSubsetScoreKeepsThePlane) {
  const BoxScene s = MakeBoxScene(0.001);
  CompletionOptions options = Refined();
  options.target_points = 1000;
  const auto reduced = CompleteShape(s.view, options);
  ASSERT_TRUE(reduced);
  std::cout << reduced->input_points << " points → " << reduced->filtered_points << "\n";
  ASSERT_GT(reduced->input_points, 3000u);
  EXPECT_GT(reduced->filtered_points, 600u);
  EXPECT_LT(reduced->filtered_points, 1250u);
  options.target_points = reduced->input_points;  // nothing to reduce: only the outlier filter acts
  const auto full = CompleteShape(s.view, options);
  // The outlier cut at μ + 2σ takes the tail of a near-normal spread: ~2 %.
  EXPECT_GT(full->filtered_points, reduced->input_points * 97 / 100);
  // The paper's 7 × 5 grid: the same hypothesis wins. With 4 refinements (steps down to 0.07°) the subset's noise
  // moves the optimum by under a degree and a millimetre.
  for (int refinements : {0, 4}) {
    options.symmetry.refinements = refinements;
    options.symmetry.score_points = 0;
    const auto all = CompleteShape(s.view, options);
    options.symmetry.score_points = 500;
    const auto subset = CompleteShape(s.view, options);
    ASSERT_TRUE(all && all->plane && subset && subset->plane);
    const double angle = AxisAngleDeg(all->plane->normal, subset->plane->normal);
    const double shift = std::abs(all->plane->shift - subset->plane->shift);
    std::cout << refinements << " refinements: subset vs all " << angle << " deg, " << shift * 1e3 << " mm\n";
    EXPECT_LT(angle, refinements ? 1.0 : 1e-9);
    EXPECT_LT(shift, refinements ? 1e-3 : 1e-12);
  }
}

// A cylinder (r = 4 cm, h = 10 cm) on the table z = 0 seen by a 640 × 480 camera from 30° above, completed at depth
// 7 with the table known: the mesh against the exact cylinder, both ways. The search runs over shifts only
// (orientations = 1): every vertical plane through the axis is a symmetry of a cylinder, and only the one facing the
// camera completes it (see CylinderPlaneContainsTheAxis).
TEST(ShapeCompletionTest, CylinderSeenFromOneSideIsCompletedWithinOneMillimetre) {
  const double r = 0.04, h = 0.10;
  const Vec3 centre(0.0, 0.0, h / 2);
  PartialView view;
  view.camera_pose = EyeAt(centre, 0.5, 30 * kDeg, 30 * kDeg);
  view.image = test_render::Render(test_render::Cylinder(r, h, centre), view.camera_pose, Camera(2));
  CompletionOptions options = Refined(7);
  options.symmetry.orientations = 1;
  options.table_offset = 0;  // the unseen bottom is closed flat on the table
  const auto result = CompleteShape(view, options);
  ASSERT_TRUE(result && result->plane);
  EXPECT_TRUE(CountEdges(result->mesh).Closed());
  const Deviation d = CylinderDeviation(result->mesh, r, h, centre);
  const double axis_offset = PlaneDistance(*result->plane, centre);
  std::cout << "cylinder: " << result->input_points << " points, deviation " << d.mesh_to_shape * 1e3 << " / "
            << d.shape_to_mesh * 1e3 << " mm, plane " << axis_offset * 1e3 << " mm from the axis, "
            << result->mesh.TriangleCount() << " triangles\n";
  EXPECT_LT(d.Mean(), 0.001);
  EXPECT_LT(axis_offset, 0.002);
}

// The same at full resolution: a 1280 × 1024, f = 1200 px view (r 35 mm, h 110 mm, 0.6 m away, 34° up) with 1 mm
// of depth noise, all ~38k points kept (issue 22's views). The camera samples the face turned to it more densely
// than the grazing sides: the symmetry search takes the cloud spread evenly, and Poisson counts each cell once.
// Measured when set: 0.94 / 0.94 mm, plane 1.1 mm from the axis; with every pixel weighing alike, as before,
// 1.97 / 1.99 mm and 3.3 mm.
TEST(ShapeCompletionTest, CylinderKeptPointForPointIsCompletedWithinAMillimetreAndAHalf) {
  const double r = 0.035, h = 0.11;
  const Vec3 centre(0, 0, h / 2);
  CameraIntrinsics k;
  k.width = 1280, k.height = 1024, k.fx = k.fy = 1200, k.cx = 639.5, k.cy = 511.5;
  PartialView view;
  view.camera_pose = test_render::LookAt(Vec3(0.6 * std::cos(0.6), 0, 0.6 * std::sin(0.6)), centre);
  std::mt19937_64 random(11);
  std::normal_distribution<double> noise(0, 0.001);
  view.image = test_render::Render(test_render::Cylinder(r, h, centre), view.camera_pose, k,
                                   [&](int, int) { return noise(random); });
  CompletionOptions options;
  options.voxel_size = 1e-5;  // every point kept
  options.poisson.depth = 5;
  options.table_offset = 0;
  const auto result = CompleteShape(view, options);
  ASSERT_TRUE(result && result->plane);
  EXPECT_GT(result->filtered_points, 30000u);
  EXPECT_TRUE(CountEdges(result->mesh).Closed());
  const Deviation d = CylinderDeviation(result->mesh, r, h, centre);
  const double axis_offset = PlaneDistance(*result->plane, centre);
  std::cout << "cylinder, all " << result->filtered_points << " points: deviation " << d.mesh_to_shape * 1e3 << " / "
            << d.shape_to_mesh * 1e3 << " mm, plane " << axis_offset * 1e3 << " mm from the axis\n";
  EXPECT_LT(d.mesh_to_shape, 0.0015);
  EXPECT_LT(d.shape_to_mesh, 0.0015);
  EXPECT_LT(axis_offset, 0.002);
}

// A cylinder is symmetric about every vertical plane through its axis; the score cannot prefer the one facing
// the camera, and a plane turned by α leaves a gap of 2α on the back that Poisson bulges over (docs/perception.md).
// What must hold: the plane contains the axis, and the seen side is reproduced.
TEST(ShapeCompletionTest, CylinderPlaneContainsTheAxis) {
  const double r = 0.04, h = 0.10;
  const Vec3 centre(0.0, 0.0, h / 2);
  PartialView view;
  view.camera_pose = EyeAt(centre, 0.5, 30 * kDeg, 30 * kDeg);
  view.image = test_render::Render(test_render::Cylinder(r, h, centre), view.camera_pose, Camera());
  const auto result = CompleteShape(view, Refined(6));
  ASSERT_TRUE(result && result->plane);
  EXPECT_TRUE(CountEdges(result->mesh).Closed());
  const double offset = PlaneDistance(*result->plane, centre);
  std::cout << "cylinder: plane " << offset * 1e3 << " mm from the axis, turned " << result->plane->angle_deg
            << " deg\n";
  EXPECT_LT(offset, 0.002);
  const Observation seen = Observe(view, 1 << 22);
  const MeshDistance to_mesh(result->mesh);
  double mean = 0;
  for (const Vec3& p : seen.points) mean += to_mesh.Distance(p) / double(seen.points.size());
  EXPECT_LT(mean, 0.001);
}

// A cup (r = 4 cm, h = 10 cm, a 4 mm wall, open at the top) seen from 35–55° above: the camera sees into it, so the
// farthest seen point is the inner far wall and none of the paper's 5 shifts falls within 2 mm of the axis
// (measured when set: 2.2, 6.8, 4.0 mm). The shift refined at the best orientation (SymmetryParams::fine_shifts,
// step 6) finds it within 1 mm (0.06, 0.45, 0.66 mm); the service's defaults otherwise, the table known.
TEST(ShapeCompletionTest, HollowCupsPlaneIsFoundAtItsAxisNotOnThePapersShiftGrid) {
  const double r = 0.04, h = 0.10;
  const Vec3 centre(0.0, 0.0, h / 2);
  for (double elevation : {35.0, 45.0, 55.0}) {  // any azimuth gives the same image
    PartialView view;
    view.camera_pose = EyeAt(centre, 0.5, 30 * kDeg, elevation * kDeg);
    view.image = test_render::Render(test_render::Cup(r, h, r - 0.004, 0.006, centre), view.camera_pose, Camera(2));
    CompletionOptions options;
    options.table_offset = 0.0;
    options.symmetry.fine_shifts = 0;
    const auto grid = CompleteShape(view, options);
    options.symmetry.fine_shifts = CompletionOptions().symmetry.fine_shifts;
    const auto refined = CompleteShape(view, options);
    ASSERT_TRUE(grid && grid->plane && refined && refined->plane);
    const double off_grid = PlaneDistance(*grid->plane, centre), off = PlaneDistance(*refined->plane, centre);
    std::cout << "cup from " << elevation << " deg up: plane " << off * 1e3 << " mm from the axis (the grid alone "
              << off_grid * 1e3 << " mm at shift " << grid->plane->shift * 1e3 << " mm), "
              << refined->plane->hypotheses << " hypotheses\n";
    EXPECT_LT(off, 0.001);
    EXPECT_EQ(refined->plane->hypotheses, grid->plane->hypotheses + options.symmetry.fine_shifts);
  }
}

// What the camera saw empty (free_space.h), on the box view: before the seen surface by more than the depth
// margin, beside the silhouette by more than the pixel margin; not behind the surface, not inside, not what the
// camera did not look at. Before the surface the test is against the least depth of the 3 × 3 pixels around: on the
// faces seen at a grazing angle (1.8 mm per pixel here) a point 1 cm before the surface can still be behind a
// neighbouring pixel's depth, and beside a depth step (the box's near vertical edge) 5 cm before can be. Measured
// when set: 1 cm before, 97.7 % of the points' places are claimed; 5 cm before, 99.2 %.
TEST(SeenFreeSpaceTest, BeforeTheSurfaceAndBesideTheSilhouetteOnly) {
  const BoxScene s = MakeBoxScene(0.001);
  const Observation obs = Observe(s.view, 1 << 22);
  const SeenFreeSpace free_space(obs, 1.5, 0.004);
  const Vec3 eye = obs.CameraCentre();
  double tested = 0, claimed = 0, claimed_5cm = 0;
  for (size_t i = 0; i < obs.points.size(); i += 37) {
    const Vec3 ray = (obs.points[i] - eye).normalized();
    tested += 1;
    claimed += free_space.Contains(obs.points[i] - 0.01 * ray);
    claimed_5cm += free_space.Contains(obs.points[i] - 0.05 * ray);
    ASSERT_FALSE(free_space.Contains(obs.points[i] - 0.001 * ray)) << "1 mm before seen point " << i;
    ASSERT_FALSE(free_space.Contains(obs.points[i] + 0.01 * ray)) << "1 cm behind seen point " << i;
  }
  std::cout << "before the seen points: " << claimed / tested * 100 << " % claimed at 1 cm, "
            << claimed_5cm / tested * 100 << " % at 5 cm\n";
  EXPECT_GT(claimed / tested, 0.9);
  EXPECT_GT(claimed_5cm / tested, 0.98);
  EXPECT_FALSE(free_space.Contains(s.pose.position));
  const Vec3 right = s.camera.orientation * Vec3::UnitX();
  EXPECT_TRUE(free_space.Contains(s.pose.position + 0.1 * right));    // ~55 px beside the silhouette
  EXPECT_FALSE(free_space.Contains(s.pose.position + 1.0 * right));   // outside the image
  EXPECT_FALSE(free_space.Contains(eye - 0.1 * (s.pose.position - eye)));  // behind the camera
}

// The completed surface stays out of the space the camera saw empty (with the margins grown by one grid cell:
// the surface may stop at a cleared node), and without the clearing it does not: the box seen along its short
// axis, whose mirror image Poisson closes beyond the silhouette. Measured when set: none of the vertices with the
// clearing, 16.9 % without.
TEST(ShapeCompletionTest, NoSurfaceWhereTheCameraSawEmpty) {
  const BoxScene s = MakeBoxScene(0.001);
  const Observation obs = Observe(s.view, 1 << 22);
  CompletionOptions options = Refined();
  options.table_offset = 0;
  const auto cleared = CompleteShape(s.view, options);
  options.clear_seen_free_space = false;
  const auto plain = CompleteShape(s.view, options);
  ASSERT_TRUE(cleared && plain);
  EXPECT_TRUE(CountEdges(cleared->mesh).Closed());
  const double cell = cleared->poisson.cell_size;
  const double cell_px = cell * obs.intrinsics.fx / (s.pose.position - obs.CameraCentre()).norm();
  const SeenFreeSpace loose(obs, 1.5 + 1.5 * cell_px, 0.004 + 1.5 * cell);
  const auto share_inside = [&](const TriangleMesh& mesh) {
    double inside = 0;
    for (const auto& v : mesh.vertices) inside += loose.Contains(v.cast<double>());
    return inside / double(mesh.vertices.size());
  };
  const double with = share_inside(cleared->mesh), without = share_inside(plain->mesh);
  std::cout << "vertices in the space seen empty: " << with * 100 << " % cleared, " << without * 100 << " % plain\n";
  EXPECT_EQ(with, 0.0);
  EXPECT_GT(without, 0.01);
}

TEST(ShapeCompletionTest, SameInputGivesBitIdenticalMesh) {
  const BoxScene s = MakeBoxScene(0.001);
  const auto a = CompleteShape(s.view, Refined()), b = CompleteShape(s.view, Refined());
  ASSERT_TRUE(a && b);
  ASSERT_EQ(a->mesh.vertices.size(), b->mesh.vertices.size());
  ASSERT_EQ(a->mesh.triangles, b->mesh.triangles);
  EXPECT_EQ(0, std::memcmp(a->mesh.vertices.data(), b->mesh.vertices.data(),
                           a->mesh.vertices.size() * sizeof(a->mesh.vertices[0])));
  EXPECT_EQ(a->plane->point, b->plane->point);
  EXPECT_EQ(a->plane->score, b->plane->score);
}

TEST(ShapeCompletionTest, DelaunayBaselineIsAClosedShellOfTheSeenSide) {
  const BoxScene s = MakeBoxScene();
  CompletionOptions options;
  options.method = CompletionMethod::kDelaunay;
  const auto result = CompleteShape(s.view, options);
  ASSERT_TRUE(result);
  EXPECT_FALSE(result->plane);
  const EdgeCounts edges = CountEdges(result->mesh);
  EXPECT_EQ(edges.boundary, 0u);
  EXPECT_EQ(edges.misoriented, 0u);
  // Every vertex is a seen point; every sample of the shell lies on the box's surface (within the chord error
  // of triangles across its edges).
  double worst = 0, mean = 0;
  const std::vector<Vec3> samples = SampleSurface(result->mesh, 5000, 3);
  const Pose inv = s.pose.Inverse();
  for (const Vec3& p : samples) {
    const double d = std::abs(test_shapes::BoxDistance(inv * p, s.size));
    worst = std::max(worst, d);
    mean += d / samples.size();
  }
  std::cout << "delaunay: " << result->mesh.TriangleCount() << " triangles, mean " << mean * 1e3 << " mm, worst "
            << worst * 1e3 << " mm off the box\n";
  EXPECT_LT(mean, 0.002);
}

TEST(ShapeCompletionTest, FiltersDropOutliersAndMergeVoxels) {
  std::vector<Vec3> grid;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) grid.emplace_back(0.002 * i, 0.002 * j, 0);
  }
  std::vector<Vec3> with_outlier = grid;
  with_outlier.emplace_back(0.03, 0.03, 0.05);
  const std::vector<Vec3> kept = RemoveStatisticalOutliers(with_outlier, 8, 2);
  EXPECT_EQ(kept.size(), grid.size());
  EXPECT_EQ(kept, grid);
  const std::vector<Vec3> voxels = VoxelDownsample(grid, 0.004 - 1e-9);  // 2 × 2 points per voxel
  EXPECT_EQ(voxels.size(), 15u * 15u);
  EXPECT_NEAR(voxels.front().x(), 0.001, 1e-12);
  // A voxel too small for the points' coordinates (beyond 2^20 cubes along an axis) is refused naming it; before,
  // 1e-30 m merged all 900 points into one.
  EXPECT_EQ(VoxelDownsample(grid, 1e-7).size(), grid.size());
  for (double tiny : {1e-9, 1e-30, 1e-300}) {
    try {
      VoxelDownsample(grid, tiny);
      ADD_FAILURE() << "no error for voxel " << tiny;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find("voxel_size: "), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("is too small for points 0.058 m from the grid's origin"),
                std::string::npos)
          << e.what();
    }
  }
}

// Bad input names the field and the value.
void ExpectError(const PartialView& view, ErrorCode code, const std::string& text, size_t max_points = 1 << 20) {
  CompletionOptions options;
  options.max_points = max_points;
  try {
    CompleteShape(view, options);
    ADD_FAILURE() << "no error; expected " << text;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

TEST(ShapeCompletionTest, BadInputIsRejectedNamingTheField) {
  PartialView empty;
  ExpectError(empty, ErrorCode::kInvalidArgument, "cloud.points: the cloud is empty");

  PartialView line;
  line.camera_pose.position = Vec3(0, 0, -1);
  for (int i = 0; i < 100; ++i) line.points.emplace_back(0.001 * i, 0, 0);
  ExpectError(line, ErrorCode::kInvalidArgument, "lie on one line");

  PartialView big = line;
  ExpectError(big, ErrorCode::kResourceExhausted, "cloud.points: 100 points exceed the limit of 50", 50);

  PartialView nan_image;
  nan_image.image = DepthImage{Camera(), std::vector<float>(320 * 240, NAN), {}};
  ExpectError(nan_image, ErrorCode::kInvalidArgument, "depth_image.depth: no pixel has a finite, positive depth");

  PartialView bad_mask = nan_image;
  bad_mask.image->depth.assign(320 * 240, 0.5f);
  bad_mask.image->mask.assign(100, 1);
  ExpectError(bad_mask, ErrorCode::kInvalidArgument, "depth_image.mask: 100 bytes for a 320 x 240 image");

  PartialView behind;
  behind.camera_pose.position = Vec3(0, 0, 1);  // looking along +z: the points at z = 0 are behind it
  behind.points = {Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0)};
  ExpectError(behind, ErrorCode::kInvalidArgument, "cloud.points[0]: behind the camera");
}

}  // namespace
}  // namespace graspsim
