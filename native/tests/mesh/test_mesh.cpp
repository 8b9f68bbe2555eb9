// Indexed mesh: welding, degenerate removal, adjacency, face and vertex normals.
#include "tmm/mesh/mesh.hpp"
#include "tmm/mesh/stl_io.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace {

using Vec3 = Eigen::Vector3d;
constexpr double kPi = 3.14159265358979323846;

// The message of the std::invalid_argument that f throws.
std::string invalid_argument_message(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not invalid_argument: " << e.what();
    return e.what();
  }
  ADD_FAILURE() << "nothing thrown";
  return {};
}

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "'" << (text) << "' lacks '" << (part) << "'"

// A deterministic value in [-1, 1] from two integers.
double noise(uint64_t a, uint64_t b) {
  uint64_t h = a * 0x9E3779B97F4A7C15ull ^ (b + 0x632BE59BD9B4E019ull) * 0xC2B2AE3D27D4EB4Full;
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 32;
  return double(h >> 11) / double(1ull << 52) - 1.0;
}

// An nx x ny grid of unit squares, two counter-clockwise triangles each, as an indexed mesh; z = f(x, y).
// Interior vertices are moved by up to `jitter` in x and y so the triangles are irregular.
tmm::Mesh grid(int nx, int ny, const std::function<double(double, double)>& f, double jitter = 0) {
  tmm::Mesh m;
  m.V.resize((nx + 1) * (ny + 1), 3);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const bool interior = i > 0 && j > 0 && i < nx && j < ny;
      const double x = i + (interior ? jitter * noise(i, j) : 0), y = j + (interior ? jitter * noise(j, i + 7) : 0);
      m.V.row(j * (nx + 1) + i) << x, y, f(x, y);
    }
  m.F.resize(2 * nx * ny, 3);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
      m.F.row(2 * (j * nx + i)) << a, b, d;
      m.F.row(2 * (j * nx + i) + 1) << a, d, c;
    }
  return m;
}

tmm::Soup to_soup(const tmm::Mesh& m) {
  tmm::Soup s(m.F.rows(), 9);
  for (Eigen::Index t = 0; t < m.F.rows(); ++t)
    for (int k = 0; k < 3; ++k) s.block<1, 3>(t, 3 * k) = m.V.row(m.F(t, k));
  return s;
}

// Icosahedron subdivided `levels` times, projected on the sphere; counter-clockwise seen from outside.
tmm::Mesh icosphere(int levels, double radius, const Vec3& center) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                         {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (Vec3& p : v) p.normalize();
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = int(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& t : f) {
      const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      next.insert(next.end(), {{t[0], ab, ca}, {t[1], bc, ab}, {t[2], ca, bc}, {ab, bc, ca}});
    }
    f.swap(next);
  }
  tmm::Mesh m;
  m.V.resize(Eigen::Index(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i) m.V.row(Eigen::Index(i)) = (center + radius * v[i]).transpose();
  m.F.resize(Eigen::Index(f.size()), 3);
  for (std::size_t t = 0; t < f.size(); ++t) m.F.row(Eigen::Index(t)) << f[t][0], f[t][1], f[t][2];
  return m;
}

// Latitude-longitude sphere: long thin triangles near the poles, high valence at the poles.
tmm::Mesh uv_sphere(int nlon, int nlat, double radius) {
  tmm::Mesh m;
  m.V.resize(2 + nlon * (nlat - 1), 3);
  m.V.row(0) << 0, 0, radius;
  m.V.row(1) << 0, 0, -radius;
  for (int j = 1; j < nlat; ++j)
    for (int i = 0; i < nlon; ++i) {
      const double th = kPi * j / nlat, ph = 2 * kPi * i / nlon;
      m.V.row(2 + (j - 1) * nlon + i) << radius * std::sin(th) * std::cos(ph), radius * std::sin(th) * std::sin(ph),
          radius * std::cos(th);
    }
  auto at = [&](int j, int i) { return 2 + (j - 1) * nlon + (i % nlon); };
  std::vector<std::array<int, 3>> f;
  for (int i = 0; i < nlon; ++i) {
    f.push_back({0, at(1, i), at(1, i + 1)});
    f.push_back({1, at(nlat - 1, i + 1), at(nlat - 1, i)});
    for (int j = 1; j + 1 < nlat; ++j) {
      f.push_back({at(j, i), at(j + 1, i), at(j + 1, i + 1)});
      f.push_back({at(j, i), at(j + 1, i + 1), at(j, i + 1)});
    }
  }
  m.F.resize(Eigen::Index(f.size()), 3);
  for (std::size_t t = 0; t < f.size(); ++t) m.F.row(Eigen::Index(t)) << f[t][0], f[t][1], f[t][2];
  return m;
}

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180 / kPi;
}

constexpr tmm::NormalWeighting kAll[] = {tmm::NormalWeighting::Angle, tmm::NormalWeighting::Area,
                                         tmm::NormalWeighting::Meyer};

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Welding

TEST(Weld, GridSharesVerticesExactly) {
  const tmm::Mesh g = grid(30, 20, [](double x, double y) { return 0.1 * x * y; });
  const tmm::Soup soup = to_soup(g);
  std::size_t removed = 99;
  const tmm::Mesh m = tmm::weld(soup, 1e-6, &removed);
  EXPECT_EQ(removed, 0u);
  EXPECT_EQ(m.V.rows(), 31 * 21);
  ASSERT_EQ(m.F.rows(), 2 * 30 * 20);
  for (Eigen::Index t = 0; t < m.F.rows(); ++t)  // triangle order kept, corners at their soup positions
    for (int k = 0; k < 3; ++k) EXPECT_EQ(Vec3(m.V.row(m.F(t, k))), Vec3(soup.block<1, 3>(t, 3 * k).transpose()));
  EXPECT_EQ(tmm::weld(soup, 0).V.rows(), 31 * 21);  // tolerance 0: identical points only
}

TEST(Weld, JitterWithinToleranceAcrossCellBoundaries) {
  // Grid points sit on integer coordinates, i.e. exactly on hash cell boundaries; every copy of a
  // corner is moved by up to tol/4 per axis, so copies are at most 0.87 tol apart.
  const double tol = 1e-3;
  tmm::Soup soup = to_soup(grid(30, 20, [](double x, double y) { return x - y; }));
  for (Eigen::Index t = 0; t < soup.rows(); ++t)
    for (int k = 0; k < 9; ++k) soup(t, k) += 0.25 * tol * noise(uint64_t(t), uint64_t(k));
  std::size_t removed = 99;
  EXPECT_EQ(tmm::weld(soup, tol, &removed).V.rows(), 31 * 21);
  EXPECT_EQ(removed, 0u);
  EXPECT_EQ(tmm::weld(soup, 0).V.rows(), 3 * soup.rows());  // no two corners are identical
  EXPECT_EQ(tmm::weld(soup, 1e-5).V.rows(), 3 * soup.rows());
}

TEST(Weld, ToleranceIsADistance) {
  // Two triangles sharing an edge; the second one's copies of the shared corners are moved along
  // (1, 1, 1) by 0.9 tol or 1.1 tol.
  const double tol = 0.01;
  for (double factor : {0.9, 1.1}) {
    const double d = factor * tol / std::sqrt(3.0);
    tmm::Soup s(2, 9);
    s.row(0) << 0, 0, 0, 1, 0, 0, 0, 1, 0;
    s.row(1) << 1 + d, d, d, 1, 1, 0, d, 1 + d, d;
    EXPECT_EQ(tmm::weld(s, tol).V.rows(), factor < 1 ? 4 : 6) << factor;
  }
}

TEST(Weld, RandomPairsJustInsideAndOutsideTolerance) {
  // 2000 random triangles, each followed by a copy whose corners are moved 0.99 tol (merged) or
  // 1.01 tol (kept apart) in a random direction: many pairs straddle hash cell faces.
  for (double tol : {1e-3, 0.37}) {
    for (double factor : {0.99, 1.01}) {
      const int n = 2000;
      tmm::Soup s(2 * n, 9);
      for (int t = 0; t < n; ++t)
        for (int k = 0; k < 3; ++k) {
          const Vec3 p = 1000 * Vec3(noise(t, 10 * k), noise(t, 10 * k + 1), noise(t, 10 * k + 2));
          const Vec3 d = Vec3(noise(t, 10 * k + 3), noise(t, 10 * k + 4), noise(t, 10 * k + 5)).normalized();
          s.block<1, 3>(2 * t, 3 * k) = p.transpose();
          s.block<1, 3>(2 * t + 1, 3 * k) = (p + factor * tol * d).transpose();
        }
      std::size_t removed = 0;
      EXPECT_EQ(tmm::weld(s, tol, &removed).V.rows(), factor < 1 ? 3 * n : 6 * n) << tol << " " << factor;
      EXPECT_EQ(removed, 0u);
    }
  }
}

TEST(Weld, DegenerateTrianglesRemovedAndCounted) {
  tmm::Soup s(5, 9);
  s.row(0) << 0, 0, 0, 1, 0, 0, 0, 1, 0;                   // good
  s.row(1) << 5, 5, 5, 5, 5, 5, 6, 5, 5;                   // repeated corner
  s.row(2) << 0, 0, 1, 1, 1, 2, 3, 3, 4;                   // collinear: zero area
  s.row(3) << 9, 9, 9, 9 + 1e-8, 9, 9, 9, 9 + 1e-8, 9;     // collapses to a point at tol 1e-6
  s.row(4) << 0.1, 0.2, 0.3, 0.7, 0.4, 0.2, 1e6, 1e6, 1e6; // long and thin, but a real triangle
  std::size_t removed = 0;
  const tmm::Mesh m = tmm::weld(s, 1e-6, &removed);
  EXPECT_EQ(removed, 3u);
  ASSERT_EQ(m.F.rows(), 2);
  EXPECT_EQ(m.V.rows(), 6);  // vertices of removed triangles are not kept
  EXPECT_EQ(m.F.row(0), (Eigen::Matrix<int32_t, 1, 3>() << 0, 1, 2).finished());
}

TEST(Weld, Errors) {
  EXPECT_CONTAINS(invalid_argument_message([] {
                    tmm::Soup s(2, 9);
                    s.row(0) << 0, 0, 0, 0, 0, 0, 1, 1, 1;
                    s.row(1) << 0, 0, 0, 1, 1, 1, 2, 2, 2;
                    tmm::weld(s, 1e-6);
                  }),
                  "no non-degenerate triangles");
  EXPECT_CONTAINS(invalid_argument_message([] { tmm::weld(tmm::Soup(0, 9), 1e-6); }), "no triangles");
  EXPECT_CONTAINS(invalid_argument_message([] {
                    tmm::Soup s = tmm::Soup::Zero(3, 9);
                    s(1, 4) = std::nan("");
                    tmm::weld(s, 1e-6);
                  }),
                  "triangle 1 has a non-finite coordinate");
  for (double tol : {-1.0, std::nan(""), HUGE_VAL})
    EXPECT_CONTAINS(invalid_argument_message([tol] { tmm::weld(tmm::Soup::Zero(1, 9), tol); }),
                    "weld tolerance must be finite and >= 0");
}

// ---------------------------------------------------------------------------------------------------
// Adjacency

namespace {
// Every neighbour shares the edge's two vertices and lists this triangle back.
void expect_consistent_adjacency(const tmm::Mesh& m, const tmm::Adjacency& A) {
  for (Eigen::Index t = 0; t < m.F.rows(); ++t)
    for (int i = 0; i < 3; ++i) {
      const int32_t s = A(t, i);
      if (s < 0) continue;
      const int32_t a = m.F(t, i), b = m.F(t, (i + 1) % 3);
      int back = 0;
      for (int j = 0; j < 3; ++j) {
        const std::set<int32_t> e = {m.F(s, j), m.F(s, (j + 1) % 3)};
        if (e == std::set<int32_t>{a, b}) {
          EXPECT_EQ(A(s, j), t);
          ++back;
        }
      }
      EXPECT_EQ(back, 1) << "triangle " << t << " edge " << i;
    }
}
}  // namespace

TEST(Adjacency, ClosedTetrahedron) {
  tmm::Mesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  m.F.resize(4, 3);
  m.F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  const tmm::Adjacency A = tmm::triangle_adjacency(m);
  for (int t = 0; t < 4; ++t) {
    const std::set<int32_t> nb = {A(t, 0), A(t, 1), A(t, 2)};
    std::set<int32_t> others = {0, 1, 2, 3};
    others.erase(t);
    EXPECT_EQ(nb, others) << t;
  }
  EXPECT_EQ(A.row(0), (Eigen::Matrix<int32_t, 1, 3>() << 2, 3, 1).finished());  // edges 0-2, 2-1, 1-0
  expect_consistent_adjacency(m, A);
}

TEST(Adjacency, GridBoundaryIsMinusOne) {
  const tmm::Mesh m = grid(7, 5, [](double, double) { return 0.0; });
  const tmm::Adjacency A = tmm::triangle_adjacency(m);
  EXPECT_EQ((A.array() == -1).count(), 2 * (7 + 5));
  expect_consistent_adjacency(m, A);
}

TEST(Adjacency, NonManifoldEdgeHasNoNeighbour) {
  tmm::Triangles F(3, 3);
  F << 0, 1, 2, 1, 0, 3, 0, 1, 4;  // three triangles on edge 0-1
  const tmm::Adjacency A = tmm::triangle_adjacency(F);
  EXPECT_TRUE((A.array() == -1).all());
  tmm::Triangles bad(1, 3);
  bad << 0, -2, 1;
  EXPECT_CONTAINS(invalid_argument_message([&] { tmm::triangle_adjacency(bad); }), "triangle 0 has a negative vertex");
}

// ---------------------------------------------------------------------------------------------------
// Normals

TEST(FaceNormals, WindingAndDegenerate) {
  tmm::Vertices V(4, 3);
  V << 0, 0, 2, 3, 0, 2, 0, 5, 2, 6, 0, 2;
  tmm::Triangles F(3, 3);
  F << 0, 1, 2, 0, 2, 1, 0, 1, 3;
  const tmm::Normals N = tmm::face_normals(V, F);
  EXPECT_EQ(Vec3(N.row(0)), Vec3(0, 0, 1));
  EXPECT_EQ(Vec3(N.row(1)), Vec3(0, 0, -1));
  EXPECT_EQ(Vec3(N.row(2)), Vec3(0, 0, 0));
  F(1, 2) = 7;
  EXPECT_EQ(invalid_argument_message([&] { tmm::face_normals(V, F); }),
            "triangle 1 references vertex 7, but there are 4 vertices");
  V(3, 0) = HUGE_VAL;
  EXPECT_EQ(invalid_argument_message([&] { tmm::face_normals(V, F); }), "vertex 3 has a non-finite coordinate");
}

TEST(VertexNormals, PlaneIsExact) {
  const tmm::Mesh m = grid(12, 9, [](double, double) { return 5.0; }, 0.3);
  for (tmm::NormalWeighting w : kAll) {
    const tmm::Normals N = tmm::vertex_normals(m, w);
    for (Eigen::Index v = 0; v < N.rows(); ++v)
      ASSERT_EQ(Vec3(N.row(v)), Vec3(0, 0, 1)) << tmm::weighting_name(w) << " vertex " << v;
  }
}

TEST(VertexNormals, TiltedPlane) {
  tmm::Mesh m = grid(12, 9, [](double x, double y) { return 0.3 * x - 0.7 * y + 2; }, 0.3);
  const Vec3 n = Vec3(-0.3, 0.7, 1).normalized();
  for (tmm::NormalWeighting w : kAll) {
    const tmm::Normals N = tmm::vertex_normals(m, w);
    for (Eigen::Index v = 0; v < N.rows(); ++v)
      ASSERT_LT((Vec3(N.row(v)) - n).norm(), 1e-12) << tmm::weighting_name(w) << " vertex " << v;
  }
}

TEST(VertexNormals, SpheresAreRadial) {
  const Vec3 c(3, -2, 7);
  struct Case {
    const char* name;
    tmm::Mesh mesh;
    Vec3 center;
    double max_deg;
  };
  // Vertices about 3.8 (icosphere) and 2.8 (uv sphere) degrees apart seen from the centre.
  const Case cases[] = {{"icosphere", icosphere(4, 25, c), c, 0.5}, {"uv sphere", uv_sphere(128, 64, 10), Vec3::Zero(), 0.5}};
  for (const Case& k : cases)
    for (tmm::NormalWeighting w : kAll) {
      const tmm::Normals N = tmm::vertex_normals(k.mesh, w);
      double worst = 0;
      for (Eigen::Index v = 0; v < N.rows(); ++v) {
        EXPECT_NEAR(N.row(v).norm(), 1.0, 1e-12);
        worst = std::max(worst, angle_deg(N.row(v).transpose(), Vec3(k.mesh.V.row(v).transpose()) - k.center));
      }
      EXPECT_LT(worst, k.max_deg) << k.name << " " << tmm::weighting_name(w);
    }
  // Meyer's direction is really used on a sphere, not the angle-weighted fallback.
  const tmm::Mesh m = icosphere(4, 25, c);
  const tmm::Normals meyer = tmm::vertex_normals(m, tmm::NormalWeighting::Meyer);
  const tmm::Normals angle = tmm::vertex_normals(m, tmm::NormalWeighting::Angle);
  EXPECT_GT(((meyer - angle).rowwise().norm().array() > 1e-9).count(), m.V.rows() / 2);
}

TEST(VertexNormals, InsideOutSphereFollowsWinding) {
  tmm::Mesh m = icosphere(3, 1, Vec3::Zero());
  m.F.col(1).swap(m.F.col(2));
  for (tmm::NormalWeighting w : kAll) {
    const tmm::Normals N = tmm::vertex_normals(m, w);
    for (Eigen::Index v = 0; v < N.rows(); ++v) ASSERT_LT(N.row(v).dot(m.V.row(v)), -0.999) << tmm::weighting_name(w);
  }
}

TEST(VertexNormals, CurvedHeightFields) {
  // Interior vertices of an irregular grid (neighbours about 0.57 degrees apart) on a paraboloid, a
  // saddle (mean curvature small against the principal curvatures: Meyer falls back to angle
  // weighting) and a cylinder.
  struct Case {
    const char* name;
    std::function<double(double, double)> z;
    std::function<Vec3(double, double)> n;
  };
  const double R = 100;
  const Case cases[] = {
      {"paraboloid", [&](double x, double y) { return (x * x + y * y) / (2 * R); },
       [&](double x, double y) { return Vec3(-x / R, -y / R, 1).normalized(); }},
      {"saddle", [&](double x, double y) { return ((x - 10) * (x - 10) - (y - 10) * (y - 10)) / (2 * R); },
       [&](double x, double y) { return Vec3(-(x - 10) / R, (y - 10) / R, 1).normalized(); }},
      {"cylinder", [&](double x, double) { return std::sqrt(R * R - (x - 10) * (x - 10)); },
       [&](double x, double) { return Vec3((x - 10), 0, std::sqrt(R * R - (x - 10) * (x - 10))).normalized(); }},
  };
  for (const Case& k : cases) {
    const tmm::Mesh m = grid(20, 20, k.z, 0.25);
    for (tmm::NormalWeighting w : kAll) {
      const tmm::Normals N = tmm::vertex_normals(m, w);
      double worst = 0;
      for (Eigen::Index v = 0; v < N.rows(); ++v) {
        const double x = m.V(v, 0), y = m.V(v, 1);
        if (x < 1 || y < 1 || x > 19 || y > 19) continue;  // boundary vertices see a one-sided ring
        worst = std::max(worst, angle_deg(N.row(v).transpose(), k.n(x, y)));
      }
      EXPECT_LT(worst, 1.0) << k.name << " " << tmm::weighting_name(w);
    }
  }
}

TEST(VertexNormals, UnusedVertexIsZeroAndWeightingNames) {
  tmm::Vertices V(4, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 9, 9, 9;
  tmm::Triangles F(1, 3);
  F << 0, 1, 2;
  for (tmm::NormalWeighting w : kAll) {
    const tmm::Normals N = tmm::vertex_normals(V, F, w);
    EXPECT_EQ(Vec3(N.row(3)), Vec3::Zero());
    EXPECT_EQ(Vec3(N.row(0)), Vec3(0, 0, 1));
    EXPECT_EQ(tmm::parse_weighting(tmm::weighting_name(w)), w);
  }
  EXPECT_EQ(invalid_argument_message([] { tmm::parse_weighting("Angle"); }),
            "unknown vertex normal weighting 'Angle' (allowed: 'angle', 'area', 'meyer')");
}

// ---------------------------------------------------------------------------------------------------
// The shared benchmark files, end to end.

TEST(MeshFromStl, SharedFiles) {
  for (const char* name : {"beet_mm.stl", "demo.stl", "ktoolcav.stl", "mount_rush.stl", "pycam-textbox.stl",
                           "sphere_on_plate.stl", "wheel_in_box.stl"}) {
    const tmm::Soup soup = tmm::read_stl(std::string(TMM_SHARED_STL_DIR) + "/" + name);
    std::size_t removed = 0;
    const tmm::Mesh m = tmm::weld(soup, 1e-6, &removed);
    EXPECT_EQ(std::size_t(m.F.rows()) + removed, std::size_t(soup.rows())) << name;
    EXPECT_LT(m.V.rows(), soup.rows() * 3) << name;  // something was shared
    std::vector<char> used(std::size_t(m.V.rows()), 0);
    for (Eigen::Index t = 0; t < m.F.rows(); ++t)
      for (int k = 0; k < 3; ++k) used[std::size_t(m.F(t, k))] = 1;
    EXPECT_EQ(std::count(used.begin(), used.end(), 1), m.V.rows()) << name;
    expect_consistent_adjacency(m, tmm::triangle_adjacency(m));
    for (tmm::NormalWeighting w : kAll) {
      const tmm::Normals N = tmm::vertex_normals(m, w);
      EXPECT_TRUE(((N.rowwise().norm().array() - 1).abs() < 1e-9).all()) << name << " " << tmm::weighting_name(w);
    }
  }
}
