/// \file emitters_test.cpp
/// Voxelization of sources and obstacles (OpenVDB mesh-to-volume) against analytic counts.

#include "solver/emitters.h"
#include "tests/test_meshes.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

namespace plume {
namespace {

/// Axis-aligned box [lo, hi] as 12 outward-facing triangles.
EmitterMesh boxMesh(glm::vec3 lo, glm::vec3 hi, const std::string& name = "box") {
  EmitterMesh m;
  m.name = name;
  for (int n = 0; n < 8; ++n)
    m.vertices.push_back({(n & 1) ? hi.x : lo.x, (n & 2) ? hi.y : lo.y, (n & 4) ? hi.z : lo.z});
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

/// Enclosed volume and area of a closed triangle mesh (divergence theorem), in world space.
void volumeAndArea(const EmitterMesh& m, double& volume, double& area) {
  volume = area = 0.0;
  for (const glm::ivec3& t : m.triangles) {
    const glm::dvec3 a(m.vertices[t.x]), b(m.vertices[t.y]), c(m.vertices[t.z]);
    volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  volume = std::abs(volume);
}

GridFrame grid32() {
  GridFrame g;
  g.resolution = {32, 32, 32};
  g.cellSize = 1.f / 32.f;
  g.origin = {0.f, 0.f, 0.f};
  g.frameDt = 1.f / 24.f;
  return g;
}

glm::vec3 cellCentre(const GridFrame& g, std::uint32_t c) {
  const int i = int(c % std::uint32_t(g.resolution.x));
  const int j = int((c / std::uint32_t(g.resolution.x)) % std::uint32_t(g.resolution.y));
  const int k = int(c / std::uint32_t(g.resolution.x * g.resolution.y));
  return g.origin + (glm::vec3(i, j, k) + 0.5f) * g.cellSize;
}

/// Cells whose centre lies strictly inside [lo, hi] on one axis.
int centresInside(double lo, double hi, const GridFrame& g, int axis) {
  int n = 0;
  for (int i = 0; i < g.resolution[axis]; ++i) {
    const double x = g.origin[axis] + (i + 0.5) * g.cellSize;
    n += (x > lo && x < hi) ? 1 : 0;
  }
  return n;
}

void expectAscendingInGrid(const CellSet& s, const GridFrame& g) {
  const std::uint32_t count = std::uint32_t(g.resolution.x * g.resolution.y * g.resolution.z);
  ASSERT_EQ(s.cells.size(), s.velocity.size());
  for (std::size_t n = 0; n < s.cells.size(); ++n) {
    EXPECT_LT(s.cells[n], count);
    if (n) {
      EXPECT_LT(s.cells[n - 1], s.cells[n]);
    }
  }
}

TEST(Emitters, NonManifoldEdgesOfClosedAndOpenMeshes) {
  EmitterMesh box = boxMesh({0, 0, 0}, {1, 1, 1});
  EXPECT_EQ(countNonManifoldEdges(box.triangles), 0u);
  box.triangles.pop_back();  // one missing triangle: its 3 edges are now used once
  EXPECT_EQ(countNonManifoldEdges(box.triangles), 3u);
  EXPECT_EQ(countNonManifoldEdges(sphereMesh({0, 0, 0}, 1, 8, 12).triangles), 0u);
  EXPECT_EQ(countNonManifoldEdges({}), 0u);
}

TEST(Emitters, BoxObstacleCoversExactlyTheCentresInside) {
  const GridFrame g = grid32();
  // Faces between cell centres, so the analytic count has no ties.
  const glm::vec3 lo(0.2f, 0.31f, 0.13f), hi(0.61f, 0.7f, 0.5f);
  const CellSet s = voxelizeObstacle(boxMesh(lo, hi), g);
  expectAscendingInGrid(s, g);
  const int expected = centresInside(lo.x, hi.x, g, 0) * centresInside(lo.y, hi.y, g, 1) *
                       centresInside(lo.z, hi.z, g, 2);
  EXPECT_EQ(int(s.cells.size()), expected);
  for (std::uint32_t c : s.cells) {
    const glm::vec3 x = cellCentre(g, c);
    EXPECT_TRUE(x.x > lo.x && x.x < hi.x && x.y > lo.y && x.y < hi.y && x.z > lo.z && x.z < hi.z);
  }
  for (const glm::vec3& v : s.velocity) EXPECT_EQ(v, glm::vec3(0.f));
}

TEST(Emitters, SphereCellCountMatchesVolumeWithinSurfaceLayer) {
  const GridFrame g = grid32();
  const EmitterMesh sphere = sphereMesh({0.5f, 0.47f, 0.52f}, 0.3f, 32, 64);
  double volume, area;
  volumeAndArea(sphere, volume, area);
  const double cell3 = std::pow(double(g.cellSize), 3), cell2 = std::pow(double(g.cellSize), 2);
  const CellSet obstacle = voxelizeObstacle(sphere, g);
  expectAscendingInGrid(obstacle, g);
  // Inside cells approximate the volume; the error lives in one surface layer (area / Δx² cells),
  // and is far smaller on average (measured: about 1% of a layer).
  EXPECT_NEAR(double(obstacle.cells.size()), volume / cell3, 0.1 * area / cell2);
  // A source adds the cells within half a cell outside: about half a surface layer more.
  const CellSet source = voxelizeSource(sphere, g);
  EXPECT_NEAR(double(source.cells.size()), (volume + 0.5 * area * g.cellSize) / cell3,
              0.1 * area / cell2);
  EXPECT_GT(source.cells.size(), obstacle.cells.size());
}

TEST(Emitters, MatrixPlacesTheMeshInWorldSpace) {
  const GridFrame g = grid32();
  // A unit box around the origin, scaled by 0.4 and moved to (0.5, 0.5, 0.5).
  EmitterMesh box = boxMesh({-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f});
  box.matrix = glm::scale(glm::translate(glm::mat4(1.f), glm::vec3(0.5f, 0.5f, 0.51f)),
                          glm::vec3(0.41f));
  box.matrixNext = box.matrix;
  const CellSet s = voxelizeObstacle(box, g);
  const int expected = centresInside(0.295, 0.705, g, 0) * centresInside(0.295, 0.705, g, 1) *
                       centresInside(0.305, 0.715, g, 2);
  EXPECT_EQ(int(s.cells.size()), expected);
}

TEST(Emitters, PlaneSourceEmitsOneLayer) {
  const GridFrame g = grid32();
  const float dx = g.cellSize;
  // A square in the plane of the k = 8 cell centres; its edges are 0.7 Δx from the nearest
  // centres outside, so exactly 8 x 8 centres lie within half a cell of it.
  EmitterMesh plane;
  plane.name = "plane";
  const float z = 8.5f * dx, a = 4.2f * dx, b = 11.8f * dx;
  plane.vertices = {{a, a, z}, {b, a, z}, {b, b, z}, {a, b, z}};
  plane.triangles = {{0, 1, 2}, {0, 2, 3}};
  ASSERT_GT(countNonManifoldEdges(plane.triangles), 0u);
  const CellSet s = voxelizeSource(plane, g);
  expectAscendingInGrid(s, g);
  EXPECT_EQ(s.cells.size(), 64u);
  for (std::uint32_t c : s.cells) EXPECT_EQ(c / (32u * 32u), 8u);
}

TEST(Emitters, HugeOpenPlaneIsClippedToTheDomain) {
  const GridFrame g = grid32();
  EmitterMesh plane;
  plane.name = "ground";
  const float z = 3.5f * g.cellSize, r = 1e4f;
  plane.vertices = {{-r, -r, z}, {r, -r, z}, {r, r, z}, {-r, r, z}};
  plane.triangles = {{0, 1, 2}, {0, 2, 3}};
  const CellSet s = voxelizeSource(plane, g);
  EXPECT_EQ(s.cells.size(), 32u * 32u);
  for (std::uint32_t c : s.cells) EXPECT_EQ(c / (32u * 32u), 3u);
}

TEST(Emitters, OpenObstacleThrowsNamingTheObject) {
  EmitterMesh box = boxMesh({0.2f, 0.2f, 0.2f}, {0.6f, 0.6f, 0.6f}, "Leaky Cup");
  box.triangles.pop_back();
  try {
    voxelizeObstacle(box, grid32());
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'Leaky Cup'"), std::string::npos) << what;
    EXPECT_NE(what.find("not a closed manifold mesh: 3 open or non-manifold edges"),
              std::string::npos)
        << what;
  }
  EmitterMesh empty;
  empty.name = "Nothing";
  EXPECT_THROW(voxelizeObstacle(empty, grid32()), std::invalid_argument);
}

TEST(Emitters, BadMeshDataThrows) {
  EmitterMesh box = boxMesh({0.2f, 0.2f, 0.2f}, {0.6f, 0.6f, 0.6f}, "bad");
  box.triangles[3].y = 8;  // only 8 vertices: index 8 is out of range
  EXPECT_THROW(voxelizeSource(box, grid32()), std::invalid_argument);
  box = boxMesh({0.2f, 0.2f, 0.2f}, {0.6f, 0.6f, 0.6f}, "bad");
  box.vertices[2].x = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(voxelizeObstacle(box, grid32()), std::invalid_argument);
}

TEST(Emitters, CellsOutsideTheGridAreDropped) {
  const GridFrame g = grid32();
  EXPECT_TRUE(voxelizeObstacle(boxMesh({2, 2, 2}, {3, 3, 3}), g).cells.empty());
  // Half in, half out: only the part inside the grid remains.
  const CellSet s = voxelizeObstacle(boxMesh({-0.5f, 0.2f, 0.2f}, {0.3f, 0.6f, 0.6f}), g);
  expectAscendingInGrid(s, g);
  const int expected = centresInside(-0.5, 0.3, g, 0) * centresInside(0.2, 0.6, g, 1) *
                       centresInside(0.2, 0.6, g, 2);
  EXPECT_EQ(int(s.cells.size()), expected);
}

TEST(Emitters, TranslatingSourceVelocityIsItsDisplacementPerFrame) {
  const GridFrame g = grid32();
  EmitterMesh box = boxMesh({0.3f, 0.3f, 0.3f}, {0.6f, 0.6f, 0.6f});
  const glm::vec3 d(0.05f, -0.02f, 0.1f);
  box.matrixNext = glm::translate(glm::mat4(1.f), d);
  const CellSet s = voxelizeSource(box, g);
  ASSERT_FALSE(s.cells.empty());
  for (const glm::vec3& v : s.velocity) {
    EXPECT_NEAR(v.x, d.x / g.frameDt, 1e-4);
    EXPECT_NEAR(v.y, d.y / g.frameDt, 1e-4);
    EXPECT_NEAR(v.z, d.z / g.frameDt, 1e-4);
  }
}

TEST(Emitters, RotatingObstacleVelocityIsTheRigidMotion) {
  const GridFrame g = grid32();
  EmitterMesh box = boxMesh({-0.2f, -0.1f, -0.15f}, {0.2f, 0.1f, 0.15f});
  const glm::vec3 centre(0.5f, 0.5f, 0.5f);
  const float angle = 0.1f;
  box.matrix = glm::rotate(glm::translate(glm::mat4(1.f), centre), 0.3f, glm::vec3(0, 0, 1));
  box.matrixNext = glm::rotate(box.matrix, angle, glm::vec3(0, 0, 1));
  const CellSet s = voxelizeObstacle(box, g);
  ASSERT_FALSE(s.cells.empty());
  const float c = std::cos(angle), sn = std::sin(angle);
  for (std::size_t n = 0; n < s.cells.size(); ++n) {
    // Rotation by `angle` about the z axis through `centre`, over one frame.
    const glm::vec3 r = cellCentre(g, s.cells[n]) - centre;
    const glm::vec3 moved(c * r.x - sn * r.y, sn * r.x + c * r.y, r.z);
    const glm::vec3 expected = (moved - r) / g.frameDt;
    EXPECT_NEAR(s.velocity[n].x, expected.x, 1e-3);
    EXPECT_NEAR(s.velocity[n].y, expected.y, 1e-3);
    EXPECT_NEAR(s.velocity[n].z, expected.z, 1e-3);
  }
}

}  // namespace
}  // namespace plume
