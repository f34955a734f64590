/// \file flame_raster.cpp
/// rasterizeFire() for the scalar grids, points::rasterizeTrilinear for colour and velocity.

#include "flames/flame_raster.h"

#include "core/parallel.h"
#include "fields/fire_raster.h"
#include "fields/point_arrays.h"
#include "fields/velocity_extend.h"
#include "io/vdb_grids.h"

#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/points/PointRasterizeTrilinear.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace plume {
namespace {

openvdb::Vec3SGrid::Ptr vectorGrid(openvdb::Vec3STree::Ptr tree, const char* name,
                                   const openvdb::math::Transform::Ptr& xform, openvdb::VecType type) {
  auto grid = tree ? openvdb::Vec3SGrid::create(tree) : openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
  grid->setName(name);
  grid->setTransform(xform);
  grid->setGridClass(openvdb::GRID_UNKNOWN);
  grid->setVectorType(type);
  return grid;
}

}  // namespace

void FlameRasterParams::validate() const {
  if (!(voxelSize > 0.f) || !std::isfinite(voxelSize))
    throw std::invalid_argument("voxel_size must be a finite number > 0 m (got " + std::to_string(voxelSize) + ")");
  if (!std::isfinite(origin.x) || !std::isfinite(origin.y) || !std::isfinite(origin.z))
    throw std::invalid_argument("origin must be finite");
  if (!(temperatureScale > 0.f && temperatureScale <= 1e5f))
    throw std::invalid_argument("temperature_scale must be in (0, 100000] K (got " + std::to_string(temperatureScale) + ")");
  if (!(emissionScale > 0.f) || !std::isfinite(emissionScale))
    throw std::invalid_argument("light_unit must be a finite number > 0 W per W of eq. 5 (got " +
                                std::to_string(emissionScale) + ")");
  if (!(opacity >= 0.f && opacity <= 1e4f))
    throw std::invalid_argument("opacity must be in [0, 10000] (got " + std::to_string(opacity) + ")");
  if (!(blurReach >= 0.f && blurReach <= 1e3f))
    throw std::invalid_argument("blur_reach must be in [0, 1000] m (got " + std::to_string(blurReach) + ")");
  if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: all cores)");
}

FlameGrids rasterizeFlames(const FlameParticles& parts, const FlameRasterParams& params) {
  params.validate();
  initializeOpenVdb();
  const float h = params.voxelSize, cell = h * h * h;
  // Conserving splats with a particle volume of Δx³: the emission's red channel U P_i c_i.r with
  // the temperatures T_i = T_scale d_i (temperature, flame), its green and blue channels, then
  // the opacity weight d_i mass_i.
  const std::size_t n = parts.size();
  std::vector<float> red(n), green(n), blue(n), temperature(n), opacity(n), none(n, 0.f);
  for (std::size_t m = 0; m < n; ++m) {
    const float e = params.emissionScale * parts.power[m] / cell;
    red[m] = e * parts.colors[m].x;
    green[m] = e * parts.colors[m].y;
    blue[m] = e * parts.colors[m].z;
    temperature[m] = params.temperatureScale * parts.density[m];
    opacity[m] = params.opacity * parts.density[m] * parts.mass[m] / cell;
  }
  FireRasterParams fire;
  fire.voxelSize = h;
  fire.origin = params.origin;
  fire.particleVolume = cell;
  fire.ambientTemperature = 0.f;
  fire.ignitionTemperature = 0.f;
  fire.maxTemperature = params.temperatureScale;
  fire.threads = params.threads;
  fire.spacingScale = 0.f;  // the trilinear hat of one voxel, which the flames' look is tuned to
  const FireGrids scalars = rasterizeFire({parts.positions.data(), red.data(), temperature.data(), n}, fire);
  const FireGrids greens = rasterizeFire({parts.positions.data(), green.data(), none.data(), n}, fire);
  const FireGrids blues = rasterizeFire({parts.positions.data(), blue.data(), none.data(), n}, fire);
  const FireGrids opacityGrids = rasterizeFire({parts.positions.data(), opacity.data(), none.data(), n}, fire);
  FlameGrids out;
  out.density = opacityGrids.density;
  out.temperature = scalars.temperature;
  out.flame = scalars.flame;

  ThreadLimit limit(params.threads);
  const auto xform = cellCenteredTransform(h, params.origin);
  openvdb::Vec3STree::Ptr color, velocity;
  if (n > 0) {
    namespace pts = openvdb::points;
    const Vec3Points<openvdb::Vec3R> positions{parts.positions.data(), parts.size()};
    auto index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positions, *xform);
    auto points = pts::createPointDataGrid<pts::NullCodec, pts::PointDataGrid>(*index, positions, *xform);
    auto& tree = points->tree();
    pts::appendAttribute<openvdb::Vec3f>(tree, "color");
    pts::appendAttribute<openvdb::Vec3f>(tree, "velocity");
    pts::populateAttribute(tree, index->tree(), "color", Vec3Points<openvdb::Vec3f>{parts.colors.data(), parts.size()});
    pts::populateAttribute(tree, index->tree(), "velocity", Vec3Points<openvdb::Vec3f>{parts.velocities.data(), parts.size()});
    color = pts::rasterizeTrilinear</*Staggered=*/false, openvdb::Vec3f>(tree, "color");
    velocity = pts::rasterizeTrilinear</*Staggered=*/false, openvdb::Vec3f>(tree, "velocity");
  }
  out.color = vectorGrid(color, "color", xform, openvdb::VEC_INVARIANT);
  // The three channels share their topology (the same particles, the same kernel).
  auto emission = openvdb::Vec3STree::Ptr(new openvdb::Vec3STree(scalars.density->tree(), openvdb::Vec3s(0.f),
                                                                  openvdb::TopologyCopy()));
  {
    auto g = greens.density->getConstAccessor();
    auto b = blues.density->getConstAccessor();
    for (auto it = scalars.density->cbeginValueOn(); it; ++it) {
      const openvdb::Coord ijk = it.getCoord();
      emission->setValueOn(ijk, openvdb::Vec3s(*it, g.getValue(ijk), b.getValue(ijk)));
    }
  }
  out.emission = vectorGrid(emission, "emission", xform, openvdb::VEC_INVARIANT);
  out.velocity = vectorGrid(velocity, "velocity", xform, openvdb::VEC_CONTRAVARIANT_RELATIVE);
  if (params.blurReach > 0.f) {
    VelocityExtendParams extend;
    extend.voxelSize = 4.f * h;
    extend.origin = params.origin;
    extend.reach = params.blurReach;
    out.velocity = extendedVelocity(parts.positions, parts.velocities, extend);
  }
  return out;
}

void writeFlameVdb(const std::string& path, const FlameGrids& grids, int frame) {
  if (!grids.emission || !grids.density || !grids.temperature || !grids.flame || !grids.color || !grids.velocity)
    throw std::invalid_argument("flame VDB '" + path + "': missing grids");
  openvdb::GridPtrVec list{grids.emission, grids.density, grids.temperature, grids.flame, grids.color, grids.velocity};
  openvdb::MetaMap meta;
  meta.insertMeta("creator", openvdb::StringMetadata("plume"));
  meta.insertMeta("frame", openvdb::Int32Metadata(frame));
  writeGridsAtomic(path, list, meta);
}

}  // namespace plume
