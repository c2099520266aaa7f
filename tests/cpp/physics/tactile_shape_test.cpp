// Shape recognition with a tactile pad (PAPERS.md part B, experiment 5): a cube with a cross-shaped pocket in one
// face and a square pocket in the other, each face in turn lying on an upward pad; the thresholded tactile image
// shows the pocket as the untouched texels. Object: physics/holed_cube.h. Pad: a welded stand as in
// tactile_contact_test.cpp, 14 × 14 texels at the DSA 9205's 3.4 mm pitch (47.6 mm square, inside the 50 mm
// face), one sensing element per texel; the real 6 × 14 pad is checked too.
//
// Writing the documentation images (docs/physics.md, "Tactile shape recognition"):
//   GRASPSIM_TACTILE_PNG_DIR=docs build/bin/graspsim_tests --gtest_filter='TactileShape*WriteImages'
//     --gtest_also_run_disabled_tests        (one command line)
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "physics/holed_cube.h"
#include "physics/pad_stand.h"
#include "physics/simulation.h"
#include "tactile/heat_map.h"
#include "tactile/tactile_frame.h"

namespace graspsim {
namespace {

using test_objects::ExperimentCube;
using test_objects::HoledCube;

constexpr double kAluminium = 2700;  // kg/m³: the 5 cm cube weighs 0.327 kg
constexpr double kFoam = 0.004;      // m, the DSA 9205's foam

// Which face of the cube lies on the pad.
enum class Face { kCross, kSquare, kPlain };

const char* Name(Face face) {
  switch (face) {
    case Face::kCross: return "cross";
    case Face::kSquare: return "square";
    case Face::kPlain: return "plain";
  }
  return "?";
}

struct PadLayout {
  unsigned rows = 14, cols = 14;
  double pitch = 0.0034;
  unsigned subdivision = 1;
};

// Where the cube lies: its face centre off the pad centre, turned about the vertical.
struct Placement {
  double x = 0, y = 0;  // m
  double yaw = 0;       // rad
};

// A binary tactile image, row-major like TactileFrame.
using Mask = std::vector<bool>;

// A welded stand carrying an upward pad at the origin (no collision geometry: only the pad touches), and the
// holed cube lying with `face` down on the foam.
struct ShapeWorld {
  HoledCube cube = ExperimentCube();
  std::shared_ptr<SceneModel> model = std::make_shared<SceneModel>();
  SceneState state;
  Face face;
  Pose cube_pose;  // the initial one

  ShapeWorld(Face face, const PadLayout& layout, const Placement& placement = {}) : face(face) {
    TactileArraySpec pad = test_objects::StandPad(layout.subdivision);
    pad.rows = layout.rows;
    pad.cols = layout.cols;
    pad.pitch = layout.pitch;
    pad.thickness = kFoam;
    test_objects::AddPadStand(model.get(), pad);
    BodySpec object;
    object.id = "holed_cube";
    object.motion = BodyMotion::kFree;
    Geometry geometry;
    geometry.kind = Geometry::Kind::kMesh;
    geometry.mesh = std::make_shared<TriangleMesh>(test_objects::HoledCubeMesh(cube));
    object.collision.push_back(geometry);
    object.inertial = test_objects::HoledCubeInertial(cube, kAluminium);
    model->bodies.push_back(object);
    model->simulation.sleep_time = 0;
    model->Reindex();
    // Body +z (the cross) down: half a turn about x; −z (the square) down: as built; +x (plain) down: a quarter
    // turn about y.
    Quat down = Quat::Identity();
    if (face == Face::kCross) down = Quat(Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitX()));
    if (face == Face::kPlain) down = Quat(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitY()));
    cube_pose.orientation = Quat(Eigen::AngleAxisd(placement.yaw, Vec3::UnitZ())) * down;
    // The face 1 µm into the foam: it settles from there.
    cube_pose.position = Vec3(placement.x, placement.y, kFoam + cube.side / 2 - 1e-6);
    state.body_poses = {Pose(), cube_pose};
    state.joint_positions.clear();
  }

  // Lets the cube settle on the pad under gravity for `seconds` and returns the frame. The foam under the cube is
  // overdamped (time constant c / k = 10 ms): a quarter of a second leaves nothing of the start.
  TactileFrame Settle(double seconds = 0.25) {
    Simulation simulation(model);
    simulation.PrepareState(&state);
    simulation.Step(&state, static_cast<int>(std::lround(seconds / model->simulation.time_step)));
    return ReadTactileArray(*model, state, 0);
  }

  // Is the pad-frame point (x, y) under solid material of the face lying on the pad (at its initial pose)?
  bool SolidAt(double x, double y) const {
    const Vec3 world(x, y, cube_pose.position.z() - cube.side / 2);  // on the plane of the lower face
    const Vec3 body = cube_pose.Inverse() * world;
    const double h = cube.side / 2;
    switch (face) {
      case Face::kCross: return test_objects::FaceIsSolid(cube, true, body.x(), body.y());
      case Face::kSquare: return test_objects::FaceIsSolid(cube, false, body.x(), body.y());
      case Face::kPlain: return std::abs(body.y()) < h && std::abs(body.z()) < h;
    }
    return false;
  }

  // The expected contact mask: texels whose sensing area (the pitch × pitch square) is at least half on solid
  // material, measured on a 40 × 40 grid of points per texel.
  Mask ExpectedContact() const {
    const TactileArraySpec& pad = model->tactile_arrays[0];
    constexpr int kSamples = 40;
    Mask mask(size_t{pad.rows} * pad.cols);
    for (unsigned r = 0; r < pad.rows; ++r) {
      for (unsigned c = 0; c < pad.cols; ++c) {
        int solid = 0;
        for (int i = 0; i < kSamples; ++i) {
          for (int j = 0; j < kSamples; ++j) {
            const double x = (c + (i + 0.5) / kSamples) * pad.pitch - 0.5 * pad.cols * pad.pitch;
            const double y = (r + (j + 0.5) / kSamples) * pad.pitch - 0.5 * pad.rows * pad.pitch;
            solid += SolidAt(x, y);
          }
        }
        mask[size_t{r} * pad.cols + c] = 2 * solid >= kSamples * kSamples;
      }
    }
    return mask;
  }
};

// Texels with an intensity above `threshold`.
Mask Threshold(const TactileFrame& frame, unsigned threshold = 0) {
  Mask mask(frame.intensities.size());
  for (size_t t = 0; t < mask.size(); ++t) mask[t] = frame.intensities[t] > threshold;
  return mask;
}

Mask Not(const Mask& mask) {
  Mask out(mask.size());
  for (size_t t = 0; t < mask.size(); ++t) out[t] = !mask[t];
  return out;
}

// Intersection over union; two empty masks agree completely.
double IoU(const Mask& a, const Mask& b) {
  size_t both = 0, either = 0;
  for (size_t t = 0; t < a.size(); ++t) {
    both += a[t] && b[t];
    either += a[t] || b[t];
  }
  return either == 0 ? 1.0 : double(both) / double(either);
}

size_t Count(const Mask& mask) { return static_cast<size_t>(std::count(mask.begin(), mask.end(), true)); }

// The image as text, pad +y up: '#' contact, '.' none; beside it the expected mask.
std::string Picture(const Mask& image, const Mask& expected, unsigned rows, unsigned cols) {
  std::ostringstream out;
  for (unsigned r = rows; r-- > 0;) {
    for (unsigned c = 0; c < cols; ++c) out << (image[size_t{r} * cols + c] ? '#' : '.');
    out << "   ";
    for (unsigned c = 0; c < cols; ++c) out << (expected[size_t{r} * cols + c] ? '#' : '.');
    out << '\n';
  }
  return out.str();
}

// One pressing: the frame, the thresholded image and the expected contact mask, with the IoUs of the contact
// masks and of their complements (the pocket as the pad sees it).
struct Pressing {
  TactileFrame frame;
  Mask image, expected;
  double contact_iou = 0, pocket_iou = 0;
  std::string picture;
  double load = 0;  // N, the pad's normal force
};

Pressing Press(Face face, const PadLayout& layout, const Placement& placement = {}, unsigned threshold = 0) {
  ShapeWorld world(face, layout, placement);
  Pressing p;
  p.frame = world.Settle();
  p.image = Threshold(p.frame, threshold);
  p.expected = world.ExpectedContact();
  p.contact_iou = IoU(p.image, p.expected);
  p.pocket_iou = IoU(Not(p.image), Not(p.expected));
  p.picture = Picture(p.image, p.expected, layout.rows, layout.cols);
  p.load = -p.frame.force_sum.z();
  return p;
}

double CubeWeight() { return test_objects::HoledCubeInertial(ExperimentCube(), kAluminium).mass * 9.81; }

// Every directed edge (a, b) must appear once, and (b, a) once: each edge in exactly two triangles, which run
// it in opposite directions.
TEST(TactileShapeTest, HoledCubeMeshIsClosedAndOrientedOutward) {
  const HoledCube cube = ExperimentCube();
  const TriangleMesh mesh = test_objects::HoledCubeMesh(cube);
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  size_t bad = 0;
  for (const auto& [edge, count] : directed) {
    const auto back = directed.find({edge.second, edge.first});
    bad += count != 1 || back == directed.end() || back->second != 1;
  }
  EXPECT_EQ(bad, 0u) << "of " << directed.size() << " directed edges";
  // No degenerate triangles and no repeated vertices.
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]].cast<double>(), b = mesh.vertices[t[1]].cast<double>(),
               c = mesh.vertices[t[2]].cast<double>();
    ASSERT_GT((b - a).cross(c - a).norm(), 1e-12);
  }
  // Euler characteristic 2: a closed surface of genus 0 (pockets are dents, not tunnels).
  EXPECT_EQ(long(mesh.vertices.size()) - long(directed.size() / 2) + long(mesh.triangles.size()), 2);
  // The divergence theorem with counter-clockwise-outward triangles gives the solid's volume, positive:
  // 125 cm³ less the cross (2 × 40 × 8 − 8 × 8 mm², 5 mm deep) and the square (15 × 15 mm², 5 mm deep).
  double volume = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]].cast<double>(), b = mesh.vertices[t[1]].cast<double>(),
               c = mesh.vertices[t[2]].cast<double>();
    volume += a.dot(b.cross(c)) / 6;
  }
  const double expected = 125e-6 - (2 * 40 * 8 - 64) * 5e-9 - 15 * 15 * 5e-9;
  EXPECT_NEAR(volume / expected, 1.0, 1e-5);
  const Inertial inertial = test_objects::HoledCubeInertial(cube, kAluminium);
  EXPECT_NEAR(inertial.mass, kAluminium * expected, 1e-9);
  // The cross takes more material from +z than the square from −z: the centre of mass sits below the middle.
  EXPECT_LT(inertial.center_of_mass.z(), 0);
  EXPECT_NEAR(inertial.center_of_mass.head<2>().norm(), 0, 1e-12);
}

TEST(TactileShapeTest, CrossAndSquareFacesShowTheirShapes) {
  const PadLayout layout;  // 14 × 14 at 3.4 mm, one element per texel
  const Pressing cross = Press(Face::kCross, layout);
  const Pressing square = Press(Face::kSquare, layout);
  for (const Pressing* p : {&cross, &square}) {
    // Printed for tests/bench/run tactile ("shape_iou").
    std::cout << std::fixed << std::setprecision(4) << "contact IoU = " << p->contact_iou
              << ", pocket IoU = " << p->pocket_iou << "\n";
    EXPECT_GE(p->contact_iou, 0.8) << p->picture;
    EXPECT_GE(p->pocket_iou, 0.8) << p->picture;
    // The pad carries the cube.
    EXPECT_NEAR(p->load / CubeWeight(), 1.0, 5e-3);
  }
  // Centred, each pocket edge runs between element rows: the images are the expected masks exactly.
  EXPECT_EQ(cross.contact_iou, 1.0) << cross.picture;
  EXPECT_EQ(square.contact_iou, 1.0) << square.picture;
  EXPECT_EQ(Count(Not(cross.image)), 44u);   // two arms 12 texels long, 2 wide, sharing 4
  EXPECT_EQ(Count(Not(square.image)), 16u);  // 4 × 4
  // The two shapes are told apart by their pockets: the cross's pocket against the square's is a poor match.
  // (The contact masks themselves share the whole rim: their IoU is high whatever the pockets.)
  EXPECT_LT(IoU(Not(cross.image), Not(square.expected)), 0.3);
  EXPECT_LT(IoU(Not(square.image), Not(cross.expected)), 0.3);
  // Control: the plain face touches every texel.
  const Pressing plain = Press(Face::kPlain, layout);
  EXPECT_EQ(Count(plain.image), 196u) << plain.picture;
  EXPECT_NEAR(plain.load / CubeWeight(), 1.0, 5e-3);
}

TEST(TactileShapeTest, ShapesSurviveOffCentreAndTurnedPlacements) {
  // Off the texel grid (pocket edges across texels) and turned 10° about the vertical (edges slanting across
  // them). One element per texel samples the texel's centre, which lies on the side of a straight edge holding
  // at least half of the texel: only texels cut by a pocket corner can disagree with the mask.
  const PadLayout layout;
  for (const Placement& placement :
       {Placement{0.0009, -0.0006, 0}, Placement{0.0003, 0.0007, 10 * std::numbers::pi / 180}}) {
    for (Face face : {Face::kCross, Face::kSquare}) {
      const Pressing p = Press(face, layout, placement);
      EXPECT_GE(p.contact_iou, 0.8) << Name(face) << "\n" << p.picture;
      EXPECT_GE(p.pocket_iou, 0.8) << Name(face) << "\n" << p.picture;
    }
  }
}

TEST(TactileShapeTest, SubdividedPadsWidenTheContactByUpToHalfATexel) {
  // With s × s elements per texel, "any intensity" marks every texel a solid edge merely reaches into: the
  // contact image grows by up to half a texel (less one element) beyond the >= 50 % mask and the pocket shrinks.
  // The contact masks still match (IoU >= 0.8), but one element per texel (its centre: on the side of a straight
  // edge that holds at least half of the texel) never shows the pocket worse.
  for (const Placement& placement : {Placement{}, Placement{0.0009, -0.0006, 0},
                                     Placement{0.0003, 0.0007, 10 * std::numbers::pi / 180}}) {
    for (Face face : {Face::kCross, Face::kSquare}) {
      PadLayout layout;
      const Pressing centre = Press(face, layout, placement);
      for (unsigned s : {2u, 4u}) {
        layout.subdivision = s;
        const Pressing p = Press(face, layout, placement);
        EXPECT_GE(p.contact_iou, 0.8) << Name(face) << " s = " << s << "\n" << p.picture;
        EXPECT_GE(centre.pocket_iou, p.pocket_iou) << Name(face) << " s = " << s << "\n" << p.picture;
        EXPECT_NEAR(p.load / CubeWeight(), 1.0, 5e-3);
      }
    }
  }
}

TEST(TactileShapeTest, Dsa9205PadSeesA20MillimetreWindow) {
  // The real pad (6 columns × 14 rows at 3.4 mm: 20.4 × 47.6 mm) has the same pitch, so the 8 mm arms and the
  // 15 mm square are resolved as well; but its 20.4 mm width cuts the cross's 40 mm arm along x, which crosses
  // the whole pad: the cross reads as a 2-column slot crossed by a full-width band.
  PadLayout layout;
  layout.cols = 6;
  const Pressing cross = Press(Face::kCross, layout);
  const Pressing square = Press(Face::kSquare, layout);
  EXPECT_EQ(cross.contact_iou, 1.0) << cross.picture;
  EXPECT_EQ(square.contact_iou, 1.0) << square.picture;
  EXPECT_EQ(Count(Not(cross.image)), 32u) << cross.picture;   // 12 × 2 along y, 2 × 6 across, sharing 4
  EXPECT_EQ(Count(Not(square.image)), 16u) << square.picture;  // 4 × 4, one solid column each side
  for (unsigned r : {6u, 7u}) {  // the band across: no contact from edge to edge
    for (unsigned c = 0; c < 6; ++c) EXPECT_FALSE(cross.image[r * 6 + c]) << cross.picture;
  }
  EXPECT_LT(IoU(Not(cross.image), Not(square.expected)), 0.5);
}

// Writes docs/tactile-shapes-{cross,square}.png (and prints the IoUs and text images): run explicitly, see the
// top of this file.
TEST(TactileShapeTest, DISABLED_WriteImages) {
  const char* dir = std::getenv("GRASPSIM_TACTILE_PNG_DIR");
  ASSERT_NE(dir, nullptr) << "set GRASPSIM_TACTILE_PNG_DIR to the output directory (e.g. docs)";
  const PadLayout layout;
  for (Face face : {Face::kCross, Face::kSquare, Face::kPlain}) {
    const Pressing p = Press(face, layout);
    std::cout << Name(face) << " face, 14 x 14 pad: load " << p.load << " N, contact IoU " << p.contact_iou
              << ", pocket IoU " << p.pocket_iou << ", max intensity "
              << *std::max_element(p.frame.intensities.begin(), p.frame.intensities.end()) << "\n"
              << p.picture;
    if (face == Face::kPlain) continue;
    // Scaled to the hottest texel: the cube's weight is far below the 3 N-per-texel full scale.
    const unsigned max = *std::max_element(p.frame.intensities.begin(), p.frame.intensities.end());
    const std::string path = std::string(dir) + "/tactile-shapes-" + Name(face) + ".png";
    std::ofstream(path, std::ios::binary) << TactileImagePng(p.frame, max, 16);
    std::cout << "wrote " << path << "\n";
  }
  PadLayout dsa;
  dsa.cols = 6;
  for (Face face : {Face::kCross, Face::kSquare}) {
    const Pressing p = Press(face, dsa);
    std::cout << Name(face) << " face, DSA 9205 (6 x 14): contact IoU " << p.contact_iou << ", pocket IoU "
              << p.pocket_iou << "\n" << p.picture;
  }
  {
    const Pressing cross = Press(Face::kCross, layout), square = Press(Face::kSquare, layout);
    std::cout << "cross image vs square masks: contact IoU " << IoU(cross.image, square.expected) << ", pocket IoU "
              << IoU(Not(cross.image), Not(square.expected)) << "\nsquare image vs cross masks: contact IoU "
              << IoU(square.image, cross.expected) << ", pocket IoU " << IoU(Not(square.image), Not(cross.expected))
              << "\n";
  }
  const Placement centred, off{0.0009, -0.0006, 0}, turned{0.0003, 0.0007, 10 * std::numbers::pi / 180};
  for (const auto& [label, placement] :
       {std::pair{"centred", centred}, std::pair{"off-centre", off}, std::pair{"turned 10 deg", turned}}) {
    for (unsigned s : {1u, 2u, 4u}) {
      PadLayout sub;
      sub.subdivision = s;
      for (Face face : {Face::kCross, Face::kSquare}) {
        const Pressing any = Press(face, sub, placement);
        unsigned full = 0;
        for (uint16_t v : any.frame.intensities) full = std::max<unsigned>(full, v);
        const Pressing half = Press(face, sub, placement, full / 2);
        std::cout << label << ", s = " << s << ", " << Name(face) << ": > 0: contact IoU " << any.contact_iou
                  << ", pocket IoU " << any.pocket_iou << "; > half: contact IoU " << half.contact_iou
                  << ", pocket IoU " << half.pocket_iou << "\n";
      }
    }
  }
}

}  // namespace
}  // namespace graspsim
