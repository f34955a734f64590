/// \file fire_raster.cpp
/// Particle rasterization shared by flow-graph fire and structural flames (see fire_raster.h):
/// OpenVDB point transfer into density, temperature and flame grids, and their frame VDB.

#include "fields/fire_raster.h"

#include "fields/point_arrays.h"

#include "core/parallel.h"
#include "io/vdb_grids.h"

#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/points/PointRasterizeTrilinear.h>
#include <openvdb/points/PointTransfer.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace plume {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using openvdb::FloatTree;
using openvdb::Index;
using openvdb::points::PointDataTree;

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// One float per point, for populateAttribute().
struct FloatArray {
  using value_type = float;
  const float* data;
  std::size_t count;
  std::size_t size() const { return count; }
  void get(float& value, std::size_t n) const { value = data[n]; }
  void get(float& value, std::size_t n, Index) const { value = data[n]; }
};

/// The trilinear hat kernel of points::rasterizeTrilinear (cell-centred), without its division
/// by the weights: three sums per voxel, Σ w R (density), Σ w (weight), Σ w (T - T_amb) (heat).
struct FireTransfer : public openvdb::points::VolumeTransfer<FloatTree, FloatTree, FloatTree> {
  using BaseT = openvdb::points::VolumeTransfer<FloatTree, FloatTree, FloatTree>;
  /// The attribute types createPointDataGrid<NullCodec> and appendAttribute<float> make.
  using PositionAttribute = openvdb::points::TypedAttributeArray<openvdb::Vec3f, openvdb::points::NullCodec>;
  using FloatAttribute = openvdb::points::TypedAttributeArray<float, openvdb::points::NullCodec>;
  static constexpr Index DIM = FloatTree::LeafNodeType::DIM;
  static constexpr Index LOG2DIM = FloatTree::LeafNodeType::LOG2DIM;

  /// `p`, `r`, `t`: attribute indices of P, density and temperature (one descriptor for all
  /// leaves).
  FireTransfer(FloatTree& density, FloatTree& weight, FloatTree& heat, float ambient, std::size_t p,
               std::size_t r, std::size_t t)
      : BaseT(density, weight, heat), mAmbient(ambient), mIndex{p, r, t} {}
  FireTransfer(const FireTransfer& other)
      : BaseT(other), mAmbient(other.mAmbient), mIndex{other.mIndex[0], other.mIndex[1], other.mIndex[2]} {}

  openvdb::Int32 range(const Coord&, std::size_t) const { return 1; }

  bool startPointLeaf(const PointDataTree::LeafNodeType& leaf) {
    // The arrays are read directly: an AttributeHandle per point leaf and destination leaf
    // cost a heap allocation each (a tenth of the rasterization).
    mP = &static_cast<const PositionAttribute&>(leaf.constAttributeArray(mIndex[0]));
    mR = &static_cast<const FloatAttribute&>(leaf.constAttributeArray(mIndex[1]));
    mT = &static_cast<const FloatAttribute&>(leaf.constAttributeArray(mIndex[2]));
    return true;
  }
  bool endPointLeaf(const PointDataTree::LeafNodeType&) { return true; }
  bool finalize(const Coord&, std::size_t) { return true; }

  void rasterizePoint(const Coord& ijk, const Index id, const CoordBBox& bounds) {
    // P is the point's offset from the centre of voxel ijk, in voxels ([-0.5, 0.5]).
    const openvdb::Vec3f p = mP->getUnsafe(id);
    CoordBBox box(ijk, ijk);
    for (int a = 0; a < 3; ++a) {
      if (p[a] < 0.f) box.min()[a] -= 1;
      else box.max()[a] += 1;
    }
    box.intersect(bounds);
    if (box.empty()) return;
    float* density = this->buffer<0>();
    float* weight = this->buffer<1>();
    float* heat = this->buffer<2>();
    const auto& mask = *this->mask<0>();
    const float r = mR->getUnsafe(id), t = mT->getUnsafe(id) - mAmbient;
    for (Coord c = box.min(); c.x() <= box.max().x(); ++c.x()) {
      const float wx = 1.f - std::fabs(p.x() - float(c.x() - ijk.x()));
      const Index i = (Index(c.x()) & (DIM - 1u)) << 2 * LOG2DIM;
      for (c.y() = box.min().y(); c.y() <= box.max().y(); ++c.y()) {
        const float wy = wx * (1.f - std::fabs(p.y() - float(c.y() - ijk.y())));
        const Index ij = i + ((Index(c.y()) & (DIM - 1u)) << LOG2DIM);
        for (c.z() = box.min().z(); c.z() <= box.max().z(); ++c.z()) {
          const Index offset = ij + (Index(c.z()) & (DIM - 1u));
          if (!mask.isOn(offset)) continue;
          const float w = wy * (1.f - std::fabs(p.z() - float(c.z() - ijk.z())));
          density[offset] += w * r;
          weight[offset] += w;
          heat[offset] += w * t;
        }
      }
    }
  }

 private:
  float mAmbient;
  std::size_t mIndex[3];
  const PositionAttribute* mP = nullptr;
  const FloatAttribute* mR = nullptr;
  const FloatAttribute* mT = nullptr;
};

openvdb::FloatGrid::Ptr fogGrid(FloatTree::Ptr tree, const char* name,
                                const openvdb::math::Transform::Ptr& xform) {
  auto grid = openvdb::FloatGrid::create(tree);
  grid->setName(name);
  grid->setTransform(xform);
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  return grid;
}

}  // namespace

void FireRasterParams::validate() const {
  if (!(voxelSize > 0.f) || !std::isfinite(voxelSize))
    throw std::invalid_argument("voxel_size must be a finite number > 0 (got " +
                                std::to_string(voxelSize) + ")");
  if (!finite(origin)) throw std::invalid_argument("origin must be finite");
  if (!(particleVolume >= 0.f) || !std::isfinite(particleVolume))
    throw std::invalid_argument("particle_volume must be >= 0 m³ (0: (voxel_size/2)³; got " +
                                std::to_string(particleVolume) + ")");
  if (!std::isfinite(ambientTemperature) || !std::isfinite(ignitionTemperature) ||
      !std::isfinite(maxTemperature))
    throw std::invalid_argument("temperatures must be finite");
  if (!(maxTemperature > ignitionTemperature))
    throw std::invalid_argument("max_temperature must be > ignition_temperature (got " +
                                std::to_string(maxTemperature) + " <= " +
                                std::to_string(ignitionTemperature) + ")");
  if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: all cores)");
}

FireGrids rasterizeFire(const FireParticleView& in, const FireRasterParams& params) {
  params.validate();
  initializeOpenVdb();
  ThreadLimit limit(params.threads);
  const float h = params.voxelSize;
  const auto xform = cellCenteredTransform(h, params.origin);
  // Non-finite particles (a broken input) are left out; in the common case nothing is copied.
  FireParticleView view = in;
  std::vector<glm::vec3> keptX, keptU;
  std::vector<float> keptR, keptT;
  auto usable = [&](std::size_t n) {
    return finite(in.positions[n]) && std::isfinite(in.density[n]) && std::isfinite(in.temperature[n]) &&
           (!in.velocities || finite(in.velocities[n]));
  };
  bool allFinite = true;
  for (std::size_t n = 0; n < in.count && allFinite; ++n) allFinite = usable(n);
  if (!allFinite) {
    for (std::size_t n = 0; n < in.count; ++n)
      if (usable(n)) {
        keptX.push_back(in.positions[n]);
        keptR.push_back(in.density[n]);
        keptT.push_back(in.temperature[n]);
        if (in.velocities) keptU.push_back(in.velocities[n]);
      }
    view = {keptX.data(), keptR.data(), keptT.data(), keptX.size(), in.velocities ? keptU.data() : nullptr};
  }

  FireGrids out;
  const float ambient = params.ambientTemperature;
  auto density = std::make_shared<FloatTree>(0.f);
  auto temperature = std::make_shared<FloatTree>(ambient);
  auto flame = std::make_shared<FloatTree>(0.f);
  openvdb::Vec3STree::Ptr velocity;
  if (view.count > 0) {
    namespace pts = openvdb::points;
    const Vec3Points<openvdb::Vec3R> positions{view.positions, view.count};
    auto index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positions, *xform);
    auto points = pts::createPointDataGrid<pts::NullCodec, pts::PointDataGrid>(*index, positions, *xform);
    PointDataTree& tree = points->tree();
    pts::appendAttribute<float>(tree, "density");
    pts::appendAttribute<float>(tree, "temperature");
    pts::populateAttribute(tree, index->tree(), "density", FloatArray{view.density, view.count});
    pts::populateAttribute(tree, index->tree(), "temperature", FloatArray{view.temperature, view.count});

    // Every voxel a particle touches: the point voxels dilated by one (as rasterizeTrilinear).
    density->topologyUnion(tree);
    openvdb::tools::dilateActiveValues(*density, 1, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       openvdb::tools::EXPAND_TILES);
    FloatTree weight(*density, 0.f, openvdb::TopologyCopy());
    FloatTree heat(*density, 0.f, openvdb::TopologyCopy());
    const auto& descriptor = tree.cbeginLeaf()->attributeSet().descriptor();
    FireTransfer transfer(*density, weight, heat, ambient, descriptor.find("P"),
                          descriptor.find("density"), descriptor.find("temperature"));
    pts::rasterize(*points, transfer);

    // Per voxel: mass per volume, mean temperature, flame.
    const float volume = params.particleVolume > 0.f ? params.particleVolume : 0.125f * h * h * h;
    const float massScale = volume / (h * h * h);
    const float ignition = params.ignitionTemperature;
    const float span = params.maxTemperature - ignition;
    temperature->topologyUnion(*density);
    flame->topologyUnion(*density);
    openvdb::tree::LeafManager<FloatTree> leaves(*density);
    leaves.foreach([&](FloatTree::LeafNodeType& leaf, std::size_t) {
      const Coord o = leaf.origin();
      const auto* w = weight.probeConstLeaf(o);
      const auto* q = heat.probeConstLeaf(o);
      auto* t = temperature->probeLeaf(o);
      auto* f = flame->probeLeaf(o);
      for (auto it = leaf.beginValueOn(); it; ++it) {
        const Index m = it.pos();
        const float sumW = w->getValue(m);
        if (sumW <= 0.f) {
          // Touched by no particle's kernel (a zero weight at the dilation's rim).
          leaf.setValueOff(m, 0.f);
          t->setValueOff(m, ambient);
          f->setValueOff(m, 0.f);
          continue;
        }
        it.setValue(it.getValue() * massScale);
        const float tv = ambient + q->getValue(m) / (sumW > 1.f ? sumW : 1.f);
        t->setValueOnly(m, tv);
        const float fv = (tv - ignition) / span;
        f->setValueOnly(m, fv < 0.f ? 0.f : (fv > 1.f ? 1.f : fv));
      }
    });
    openvdb::tools::pruneInactive(*density);
    openvdb::tools::pruneInactive(*temperature);
    openvdb::tools::pruneInactive(*flame);
    if (view.velocities) {
      pts::appendAttribute<openvdb::Vec3f>(tree, "velocity");
      pts::populateAttribute(tree, index->tree(), "velocity", Vec3Points<openvdb::Vec3f>{view.velocities, view.count});
      velocity = pts::rasterizeTrilinear</*Staggered=*/false, openvdb::Vec3f>(tree, "velocity");
    }
  }
  out.density = fogGrid(density, "density", xform);
  out.temperature = fogGrid(temperature, "temperature", xform);
  out.flame = fogGrid(flame, "flame", xform);
  if (in.velocities) {
    out.velocity = velocity ? openvdb::Vec3SGrid::create(velocity) : openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
    out.velocity->setName("velocity");
    out.velocity->setTransform(xform);
    out.velocity->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
  }
  return out;
}

void writeFireVdb(const std::string& path, const FireGrids& grids, int frame) {
  if (!grids.density || !grids.temperature || !grids.flame)
    throw std::invalid_argument("fire VDB '" + path + "': missing grids");
  openvdb::GridPtrVec list{grids.density, grids.temperature, grids.flame};
  if (grids.velocity) list.push_back(grids.velocity);
  openvdb::MetaMap meta;
  meta.insertMeta("creator", openvdb::StringMetadata("plume"));
  meta.insertMeta("frame", openvdb::Int32Metadata(frame));
  writeGridsAtomic(path, list, meta);
}

}  // namespace plume
