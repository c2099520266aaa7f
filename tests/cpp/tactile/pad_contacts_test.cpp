// Pad elements as physics contacts: their feature ids round-trip and stay apart from surface samples', and a
// texel's foam law is shared out among its elements.
#include "tactile/pad_contacts.h"

#include <gtest/gtest.h>

namespace graspsim {
namespace {

TEST(PadContactsTest, FeaturesNameTheirPadAndElement) {
  for (const auto& [pad, element] : {std::pair{0u, 0u}, std::pair{3u, 167u}, std::pair{0x7fffffffu, 0xffffffffu}}) {
    const std::optional<PadElementRef> ref = PadElementOf(PadFeature(pad, element));
    ASSERT_TRUE(ref.has_value());
    EXPECT_EQ(ref->pad, pad);
    EXPECT_EQ(ref->element, element);
  }
  // A surface sample's feature, (geometry << 32) | sample, is no pad's.
  EXPECT_FALSE(PadElementOf(uint64_t{5} << 32 | 12).has_value());
}

TEST(PadContactsTest, ATexelsLawIsSharedOutAmongItsElements) {
  TactileArraySpec pad;
  pad.subdivision = 2;
  pad.placement = PadElementPlacement::kFaceCentres;  // 2 · 2 · 2 = 8 elements per texel
  const ContactParams law = ElementContactParams(pad);
  EXPECT_DOUBLE_EQ(law.stiffness, pad.contact.stiffness / 8);
  EXPECT_DOUBLE_EQ(law.damping, pad.contact.damping / 8);
  EXPECT_DOUBLE_EQ(law.bristle_stiffness, pad.contact.bristle_stiffness / 8);
  EXPECT_DOUBLE_EQ(law.bristle_damping, pad.contact.bristle_damping / 8);
  EXPECT_DOUBLE_EQ(law.static_friction, pad.contact.static_friction) << "coefficients are not shared out";
  EXPECT_DOUBLE_EQ(law.stribeck_velocity, pad.contact.stribeck_velocity);
}

}  // namespace
}  // namespace graspsim
