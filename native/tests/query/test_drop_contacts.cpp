// The facet contact's documented pruning bound (zmax, above).
#include <gtest/gtest.h>

#include "tmm/query/drop_contacts.hpp"

namespace {

TEST(FacetDrop, HonoursTheZmaxBound) {
  // A horizontal triangle at z = 2 under a bull-nose: the contact is the triangle's height (h = 0 on the flat).
  const tmm::Cutter c(3, 1);
  const double p0[3] = {-10, -10, 2}, p1[3] = {10, -10, 2}, p2[3] = {0, 10, 2}, n[3] = {0, 0, 1};
  EXPECT_EQ(tmm::facet_drop(c, 0, 0, p0, p1, p2, n), 2.0);
  EXPECT_EQ(tmm::facet_drop(c, 0, 0, p0, p1, p2, n, 2.0, 1.5), 2.0);  // the true zmax: the contact
  // A bound below `above`: the contact is not computed (whatever the triangle holds), as documented.
  EXPECT_EQ(tmm::facet_drop(c, 0, 0, p0, p1, p2, n, 1.0, 1.5), tmm::kNoContact);
  // Without `above` the bound prunes nothing.
  EXPECT_EQ(tmm::facet_drop(c, 0, 0, p0, p1, p2, n, 1.0), 2.0);
}

TEST(FacetDrop, TheBoundSubtractsTheProfileAtTheContactRadius) {
  // A plane rising in x at 45 degrees under a ball of radius 2: the contact point lies at rho = 2 sin(45)
  // uphill, where h = 2 - 2 cos(45). With zmax = the highest corner the bound never cuts the contact; a
  // `above` between the contact and zmax - h(rho) keeps it, one above the bound prunes it.
  const tmm::Cutter c(2, 2);
  const double s = std::sqrt(0.5);
  const double p0[3] = {-10, -10, -10}, p1[3] = {10, -10, 10}, p2[3] = {0, 10, 0}, n[3] = {-s, 0, s};
  const double z = tmm::facet_drop(c, 0, 0, p0, p1, p2, n);
  ASSERT_GT(z, tmm::kNoContact);
  const double bound = 10.0 - (2.0 - 2.0 * s);
  EXPECT_EQ(tmm::facet_drop(c, 0, 0, p0, p1, p2, n, 10.0, z - 1e-6), z);
  EXPECT_EQ(tmm::facet_drop(c, 0, 0, p0, p1, p2, n, z + (2.0 - 2.0 * s) + 0.5, z - 1e-6), z);
  EXPECT_EQ(tmm::facet_drop(c, 0, 0, p0, p1, p2, n, 10.0, bound + 1e-6), tmm::kNoContact);
  // Just below: the plane's contact lies below `above` anyway.
  EXPECT_EQ(tmm::facet_drop(c, 0, 0, p0, p1, p2, n, 10.0, bound - 1e-6), tmm::kNoContact);
}

}  // namespace
