/// \file emitters.cpp
/// Source and obstacle meshes voxelized with OpenVDB's mesh-to-volume (narrow-band signed or
/// unsigned distance), then read back at the solver's cell centres.

#include "solver/emitters.h"

#include "core/parallel.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace plume {
namespace {

/// Half-width of the narrow band in voxels. Two voxels are enough: we only read values within
/// half a cell of the surface, and the sign inside comes from OpenVDB's flood fill.
constexpr float kHalfWidth = 2.f;

/// Largest surface an emitter may have, in cell-size squares: beyond this OpenVDB's narrow band
/// would take gigabytes (a 100 m ground cube at 1 cm cells). Open meshes are first culled to
/// the domain, so this only bites closed meshes far larger than the domain.
constexpr double kMaxSurfaceCells = double(1 << 26);

void initializeOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

[[noreturn]] void failMesh(const std::string& kind, const std::string& name, const std::string& what) {
  std::ostringstream s;
  s << kind << " '" << name << "' " << what;
  throw std::invalid_argument(s.str());
}

bool finiteMatrix(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

/// Checks what OpenVDB would otherwise choke on: non-finite vertices or matrices, indices out of
/// range, a degenerate grid.
void validate(const std::string& kind, const EmitterMesh& mesh, const GridFrame& grid) {
  if (grid.resolution.x < 1 || grid.resolution.y < 1 || grid.resolution.z < 1)
    throw std::invalid_argument("grid resolution must be at least 1 cell per axis");
  if (!(grid.cellSize > 0.f) || !std::isfinite(grid.cellSize))
    throw std::invalid_argument("grid cell_size must be a finite number > 0");
  if (!(grid.frameDt > 0.f) || !std::isfinite(grid.frameDt))
    throw std::invalid_argument("frame_dt must be a finite number > 0");
  for (std::size_t n = 0; n < mesh.vertices.size(); ++n) {
    const glm::vec3& p = mesh.vertices[n];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      std::ostringstream s;
      s << "has a non-finite vertex (index " << n << ")";
      failMesh(kind, mesh.name, s.str());
    }
  }
  const long long count = static_cast<long long>(mesh.vertices.size());
  for (std::size_t n = 0; n < mesh.triangles.size(); ++n) {
    const glm::ivec3& t = mesh.triangles[n];
    for (int a = 0; a < 3; ++a) {
      if (t[a] < 0 || t[a] >= count) {
        std::ostringstream s;
        s << "has triangle " << n << " with vertex index " << t[a] << " outside [0, " << count
          << ")";
        failMesh(kind, mesh.name, s.str());
      }
    }
  }
  if (!finiteMatrix(mesh.matrix) || !finiteMatrix(mesh.matrixNext))
    failMesh(kind, mesh.name, "has a non-finite object matrix");
}

/// Voxel (i,j,k) of the VDB is cell (i,j,k) of the solver: voxel size Δx, voxel centres at
/// origin + (i+½, j+½, k+½) Δx.
openvdb::math::Transform::Ptr cellTransform(const GridFrame& grid) {
  auto xform = openvdb::math::Transform::createLinearTransform(double(grid.cellSize));
  const glm::dvec3 centre0 = glm::dvec3(grid.origin) + 0.5 * double(grid.cellSize);
  xform->postTranslate(openvdb::Vec3d(centre0.x, centre0.y, centre0.z));
  return xform;
}

std::vector<openvdb::Vec3s> worldPoints(const EmitterMesh& mesh) {
  std::vector<openvdb::Vec3s> points(mesh.vertices.size());
  const glm::dmat4 m(mesh.matrix);
  for (std::size_t n = 0; n < points.size(); ++n) {
    const glm::dvec4 w = m * glm::dvec4(glm::dvec3(mesh.vertices[n]), 1.0);
    points[n] = openvdb::Vec3s(float(w.x), float(w.y), float(w.z));
  }
  return points;
}

/// Index-space box [lo, hi] of the cells that may be touched by triangles with these world
/// points, grown by `pad` cells and clipped to the grid. Empty when lo > hi on some axis.
void cellBox(const std::vector<openvdb::Vec3s>& points, const std::vector<openvdb::Vec3I>& tris,
             const GridFrame& grid, int pad, glm::ivec3& lo, glm::ivec3& hi) {
  glm::dvec3 mn(std::numeric_limits<double>::max()), mx(-std::numeric_limits<double>::max());
  for (const openvdb::Vec3I& t : tris)
    for (int a = 0; a < 3; ++a) {
      const openvdb::Vec3s& p = points[t[a]];
      for (int c = 0; c < 3; ++c) {
        mn[c] = std::min(mn[c], double(p[c]));
        mx[c] = std::max(mx[c], double(p[c]));
      }
    }
  for (int c = 0; c < 3; ++c) {
    // Cell centre i sits at origin + (i + ½) Δx.
    const double a = (mn[c] - grid.origin[c]) / grid.cellSize - 0.5;
    const double b = (mx[c] - grid.origin[c]) / grid.cellSize - 0.5;
    const double l = std::max(std::floor(a) - pad, 0.0);
    const double h = std::min(std::ceil(b) + pad, double(grid.resolution[c] - 1));
    lo[c] = int(l);
    hi[c] = h < l ? int(l) - 1 : int(h);
  }
}

/// Σ triangle area / Δx²: about how many voxels the narrow band has per unit of band width.
double surfaceCells(const std::vector<openvdb::Vec3s>& points,
                    const std::vector<openvdb::Vec3I>& tris, float cellSize) {
  double area = 0.0;
  for (const openvdb::Vec3I& t : tris) {
    const openvdb::Vec3d a(points[t[0]]), b(points[t[1]]), c(points[t[2]]);
    area += 0.5 * (b - a).cross(c - a).length();
  }
  return area / (double(cellSize) * double(cellSize));
}

void checkSize(const std::string& kind, const std::string& name, double cells) {
  if (cells > kMaxSurfaceCells) {
    std::ostringstream s;
    s << "is too large for the domain's cell_size: its surface covers about " << cells
      << " cells (at most " << kMaxSurfaceCells << "); scale it down towards the domain";
    failMesh(kind, name, s.str());
  }
}

/// Clips an open mesh to the domain grown by `pad` cells (Sutherland-Hodgman per triangle, fan
/// re-triangulated). For cells inside the domain, the unsigned distance up to `pad` cells only
/// depends on the clipped part, so a huge ground plane costs no more than the domain it crosses.
void clipAgainstDomain(std::vector<openvdb::Vec3s>& points, std::vector<openvdb::Vec3I>& tris,
                  const GridFrame& grid, float pad) {
  const glm::dvec3 lo = glm::dvec3(grid.origin) - double(pad) * grid.cellSize;
  const glm::dvec3 hi = glm::dvec3(grid.origin) +
                        (glm::dvec3(grid.resolution) + double(pad)) * double(grid.cellSize);
  std::vector<openvdb::Vec3I> kept;
  kept.reserve(tris.size());
  const std::size_t originalTris = tris.size();
  std::vector<openvdb::Vec3d> poly, next;
  for (std::size_t n = 0; n < originalTris; ++n) {
    const openvdb::Vec3I t = tris[n];
    bool outside = false, inside = true;
    for (int c = 0; c < 3; ++c) {
      const double a = points[t[0]][c], b = points[t[1]][c], d = points[t[2]][c];
      outside = outside || std::max({a, b, d}) < lo[c] || std::min({a, b, d}) > hi[c];
      inside = inside && std::min({a, b, d}) >= lo[c] && std::max({a, b, d}) <= hi[c];
    }
    if (outside) continue;
    if (inside) {
      kept.push_back(t);
      continue;
    }
    poly.assign({openvdb::Vec3d(points[t[0]]), openvdb::Vec3d(points[t[1]]),
                 openvdb::Vec3d(points[t[2]])});
    for (int plane = 0; plane < 6 && !poly.empty(); ++plane) {
      const int c = plane / 2;
      const bool upper = plane % 2 == 1;
      const double bound = upper ? hi[c] : lo[c];
      auto in = [&](const openvdb::Vec3d& p) { return upper ? p[c] <= bound : p[c] >= bound; };
      next.clear();
      for (std::size_t e = 0; e < poly.size(); ++e) {
        const openvdb::Vec3d& p = poly[e];
        const openvdb::Vec3d& q = poly[(e + 1) % poly.size()];
        if (in(p)) next.push_back(p);
        if (in(p) != in(q)) {
          const double s = (bound - p[c]) / (q[c] - p[c]);
          openvdb::Vec3d x = p + s * (q - p);
          x[c] = bound;
          next.push_back(x);
        }
      }
      poly.swap(next);
    }
    if (poly.size() < 3) continue;
    const openvdb::Index32 base = openvdb::Index32(points.size());
    for (const openvdb::Vec3d& p : poly) points.emplace_back(float(p[0]), float(p[1]), float(p[2]));
    for (std::size_t v = 1; v + 1 < poly.size(); ++v)
      kept.emplace_back(base, base + openvdb::Index32(v), base + openvdb::Index32(v + 1));
  }
  tris.swap(kept);
}

/// Cells in [lo, hi] (k, then j, then i: ascending linear index) for which keep(φ) holds, with
/// φ read from the distance grid at each cell centre. Slices in parallel, joined in order.
template <typename Keep>
std::vector<std::uint32_t> selectCells(const openvdb::FloatGrid& sdf, const GridFrame& grid,
                                       glm::ivec3 lo, glm::ivec3 hi, const Keep& keep) {
  std::vector<std::uint32_t> cells;
  if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return cells;
  const int slices = hi.z - lo.z + 1;
  std::vector<std::vector<std::uint32_t>> perSlice(static_cast<std::size_t>(slices));
  parallelFor(0, slices, [&](int s) {
    const int k = lo.z + s;
    auto acc = sdf.getConstAccessor();
    std::vector<std::uint32_t>& out = perSlice[std::size_t(s)];
    for (int j = lo.y; j <= hi.y; ++j)
      for (int i = lo.x; i <= hi.x; ++i)
        if (keep(acc.getValue(openvdb::Coord(i, j, k))))
          out.push_back(std::uint32_t(i + grid.resolution.x * (j + grid.resolution.y * k)));
  });
  std::size_t total = 0;
  for (const auto& s : perSlice) total += s.size();
  cells.reserve(total);
  for (const auto& s : perSlice) cells.insert(cells.end(), s.begin(), s.end());
  return cells;
}

/// Velocity of the rigid (or affine) motion matrix -> matrixNext at each cell centre:
/// (matrixNext · matrix⁻¹ · x - x) / frameDt.
std::vector<glm::vec3> motionVelocity(const std::vector<std::uint32_t>& cells, const EmitterMesh& mesh,
                                      const GridFrame& grid, const std::string& kind) {
  std::vector<glm::vec3> velocity(cells.size(), glm::vec3(0.f));
  if (mesh.matrix == mesh.matrixNext || cells.empty()) return velocity;
  const glm::dmat4 m(mesh.matrix), mNext(mesh.matrixNext);
  const double det = glm::determinant(m);
  if (!(std::abs(det) > 1e-30) || !std::isfinite(det))
    failMesh(kind, mesh.name, "has a singular object matrix (zero scale), so its motion is undefined");
  const glm::dmat4 motion = mNext * glm::inverse(m);
  const double invDt = 1.0 / double(grid.frameDt);
  const std::size_t nx = std::size_t(grid.resolution.x), ny = std::size_t(grid.resolution.y);
  parallelFor(0, int(cells.size()), [&](int n) {
    const std::size_t c = cells[std::size_t(n)];
    const glm::dvec3 ijk(double(c % nx), double((c / nx) % ny), double(c / (nx * ny)));
    const glm::dvec3 x = glm::dvec3(grid.origin) + (ijk + 0.5) * double(grid.cellSize);
    const glm::dvec3 xNext = glm::dvec3(motion * glm::dvec4(x, 1.0));
    velocity[std::size_t(n)] = glm::vec3((xNext - x) * invDt);
  });
  return velocity;
}

std::vector<openvdb::Vec3I> vdbTriangles(const EmitterMesh& mesh) {
  std::vector<openvdb::Vec3I> tris(mesh.triangles.size());
  for (std::size_t n = 0; n < tris.size(); ++n) {
    const glm::ivec3& t = mesh.triangles[n];
    tris[n] = openvdb::Vec3I(openvdb::Index32(t.x), openvdb::Index32(t.y), openvdb::Index32(t.z));
  }
  return tris;
}

}  // namespace

std::size_t countNonManifoldEdges(const std::vector<glm::ivec3>& triangles) {
  // Every undirected edge as one 64-bit key; sorted, equal keys are adjacent, and a closed
  // manifold mesh has every key exactly twice.
  std::vector<std::uint64_t> edges;
  edges.reserve(triangles.size() * 3);
  for (const glm::ivec3& t : triangles)
    for (int a = 0; a < 3; ++a) {
      const std::uint32_t p = std::uint32_t(t[a]), q = std::uint32_t(t[(a + 1) % 3]);
      const std::uint32_t lo = std::min(p, q), hi = std::max(p, q);
      edges.push_back((std::uint64_t(lo) << 32) | hi);
    }
  std::sort(edges.begin(), edges.end());
  std::size_t bad = 0;
  for (std::size_t n = 0; n < edges.size();) {
    std::size_t m = n;
    while (m < edges.size() && edges[m] == edges[n]) ++m;
    if (m - n != 2 || (edges[n] >> 32) == (edges[n] & 0xffffffffu)) ++bad;
    n = m;
  }
  return bad;
}

CellSet voxelizeSource(const EmitterMesh& mesh, const GridFrame& grid) {
  validate("source", mesh, grid);
  CellSet result;
  if (mesh.triangles.empty()) return result;
  initializeOpenVdb();

  const std::vector<openvdb::Vec3s> points = worldPoints(mesh);
  std::vector<openvdb::Vec3I> tris = vdbTriangles(mesh);
  const bool closed = countNonManifoldEdges(mesh.triangles) == 0;
  const auto xform = cellTransform(grid);
  const float halfCell = 0.5f * grid.cellSize;

  if (closed) {
    // Inside (φ < 0, from OpenVDB's sign flood fill) or within half a cell of the surface.
    glm::ivec3 lo, hi;
    cellBox(points, tris, grid, /*pad=*/1, lo, hi);
    if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return result;
    checkSize("source", mesh.name, surfaceCells(points, tris, grid.cellSize));
    const auto sdf = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, points, tris,
                                                                         kHalfWidth);
    result.cells = selectCells(*sdf, grid, lo, hi, [halfCell](float phi) {
      return phi < 0.f || std::abs(phi) <= halfCell;
    });
  } else {
    // An open mesh (plane, disc) has no inside: emit from the cells it passes through, using an
    // unsigned distance. Triangles far outside the domain cannot matter and are dropped first.
    std::vector<openvdb::Vec3s> clipped = points;
    clipAgainstDomain(clipped, tris, grid, kHalfWidth + 1.f);
    if (tris.empty()) return result;
    glm::ivec3 lo, hi;
    cellBox(clipped, tris, grid, /*pad=*/1, lo, hi);
    if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return result;
    checkSize("source", mesh.name, surfaceCells(clipped, tris, grid.cellSize));
    const auto udf = openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(
        *xform, clipped, tris, std::vector<openvdb::Vec4I>(), kHalfWidth);
    result.cells = selectCells(*udf, grid, lo, hi, [halfCell](float phi) {
      return std::abs(phi) <= halfCell;
    });
  }
  result.velocity = motionVelocity(result.cells, mesh, grid, "source");
  return result;
}

CellSet voxelizeObstacle(const EmitterMesh& mesh, const GridFrame& grid) {
  validate("obstacle", mesh, grid);
  if (mesh.triangles.empty() || mesh.vertices.empty())
    failMesh("obstacle", mesh.name, "is empty: it has no triangles (obstacles must be watertight meshes)");
  const std::size_t open = countNonManifoldEdges(mesh.triangles);
  if (open != 0) {
    std::ostringstream s;
    s << "is not a closed manifold mesh: " << open
      << " open or non-manifold edges (obstacles must be watertight)";
    failMesh("obstacle", mesh.name, s.str());
  }
  initializeOpenVdb();

  CellSet result;
  const std::vector<openvdb::Vec3s> points = worldPoints(mesh);
  const std::vector<openvdb::Vec3I> tris = vdbTriangles(mesh);
  glm::ivec3 lo, hi;
  cellBox(points, tris, grid, /*pad=*/1, lo, hi);
  if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return result;
  checkSize("obstacle", mesh.name, surfaceCells(points, tris, grid.cellSize));
  const auto sdf = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*cellTransform(grid), points,
                                                                       tris, kHalfWidth);
  result.cells = selectCells(*sdf, grid, lo, hi, [](float phi) { return phi < 0.f; });
  result.velocity = motionVelocity(result.cells, mesh, grid, "obstacle");
  return result;
}

}  // namespace plume
