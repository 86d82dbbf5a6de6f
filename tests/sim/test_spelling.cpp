// sim/spelling.h: which known name a typed one misspells, for "did you mean" in refusals.

#include <gtest/gtest.h>

#include "sim/spelling.h"

namespace rlg::sim {
namespace {

TEST(Spelling, EditsCountInsertionsDeletionsSubstitutionsAndSwapsIgnoringCase) {
  EXPECT_EQ(EditDistance("name", "name"), 0u);
  EXPECT_EQ(EditDistance("Name", "name"), 0u);
  EXPECT_EQ(EditDistance("nmae", "name"), 1u);  // two neighbours swapped: one edit
  EXPECT_EQ(EditDistance("nam", "name"), 1u);
  EXPECT_EQ(EditDistance("duration_min", "duration_s"), 3u);
  EXPECT_EQ(EditDistance("", "abc"), 3u);
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
}

TEST(Spelling, TheNearestCloseNameIsTheOneMeant) {
  const std::vector<std::string> keys = {"name", "heat_capacity_J_per_K", "duration_s", "sample_period_s", "b0_dph",
                                         "b1_dph_per_C"};
  EXPECT_EQ(NearestName("nmae", keys), "name");
  EXPECT_EQ(NearestName("heat_capacity", keys), "heat_capacity_J_per_K");  // the unit left out
  EXPECT_EQ(NearestName("duration", keys), "duration_s");
  EXPECT_EQ(NearestName("duration_min", keys), "duration_s");  // another unit: 3 edits of 10 letters
  EXPECT_EQ(NearestName("sample_perod_s", keys), "sample_period_s");
  EXPECT_EQ(NearestName("b1_dph", keys), "b1_dph_per_C");  // its unit short, not one edit from b0_dph
  EXPECT_EQ(NearestName("b2_dph", keys), "b0_dph");
  // Too far from every name, too short a stem, or a name itself: no misspelling.
  EXPECT_EQ(NearestName("xyz", keys), "");
  EXPECT_EQ(NearestName("b", keys), "");
  EXPECT_EQ(NearestName("capacity", keys), "");
  EXPECT_EQ(NearestName("name", keys), "");
  EXPECT_EQ(NearestName("anything", {}), "");
  // Ties go to the first listed.
  EXPECT_EQ(NearestName("start", {"start_s", "start_C"}), "start_s");
}

}  // namespace
}  // namespace rlg::sim
