/// \file fire_raster.cpp
/// Particle rasterization shared by flow-graph fire and structural flames (see fire_raster.h):
/// OpenVDB point transfer into density, temperature and flame grids, and their frame VDB.

#include "fields/fire_raster.h"

#include "fields/point_arrays.h"
#include "fields/splat_radius.h"

#include "core/parallel.h"
#include "io/vdb_grids.h"

#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/points/PointTransfer.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <array>
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

/// The tent kernel of fire_raster.h in one dimension: the voxels d (offsets from the point's
/// voxel) with |d - p| < r and their weights k(d) = 1 - |d - p| / r; r = 1 is the trilinear hat.
struct Tent {
  static constexpr int kMax = 2 * 8 + 1;  ///< 2 r_max + 1 voxels
  int lo = 0, hi = -1;                    ///< offsets covered
  float k[kMax];                          ///< k(lo + i)
  float sum = 0.f;                        ///< S = Σ_d k(d), the discrete normalization
  Tent(float p, float r) {
    lo = int(std::floor(p - r)) + 1;
    hi = int(std::ceil(p + r)) - 1;
    for (int d = lo; d <= hi; ++d) sum += k[d - lo] = 1.f - std::fabs(float(d) - p) / r;
  }
};

/// Four sums per voxel, in one pass of OpenVDB's point transfer: Σ w R (density, w = k / S
/// normalized per particle), Σ k (weight), Σ k (T - T_amb) (heat) and Σ k u (momentum).
struct FireTransfer
    : public openvdb::points::VolumeTransfer<FloatTree, FloatTree, FloatTree, openvdb::Vec3STree> {
  using BaseT = openvdb::points::VolumeTransfer<FloatTree, FloatTree, FloatTree, openvdb::Vec3STree>;
  /// The attribute types createPointDataGrid<NullCodec> and appendAttribute make.
  using PositionAttribute = openvdb::points::TypedAttributeArray<openvdb::Vec3f, openvdb::points::NullCodec>;
  using FloatAttribute = openvdb::points::TypedAttributeArray<float, openvdb::points::NullCodec>;
  static constexpr Index DIM = FloatTree::LeafNodeType::DIM;
  static constexpr Index LOG2DIM = FloatTree::LeafNodeType::LOG2DIM;

  /// `index`: attribute indices of P, density, temperature, radius and velocity (-1: none; one
  /// descriptor for all leaves). `ranges`: ceil(max r_p) per point leaf, at leaf origin >> 3.
  FireTransfer(FloatTree& density, FloatTree& weight, FloatTree& heat, openvdb::Vec3STree& momentum,
               float ambient, const std::array<std::size_t, 5>& index, const openvdb::Int32Tree& ranges)
      : BaseT(density, weight, heat, momentum), mAmbient(ambient), mIndex(index), mRanges(&ranges) {}
  FireTransfer(const FireTransfer& other)
      : BaseT(other), mAmbient(other.mAmbient), mIndex(other.mIndex), mRanges(other.mRanges) {}

  /// The largest kernel reaching this leaf: the point leaves around it (r_max <= DIM).
  openvdb::Int32 range(const Coord& origin, std::size_t) const {
    openvdb::Int32 r = 1;
    const Coord c = origin >> LOG2DIM;
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k) r = std::max(r, mRanges->getValue(c.offsetBy(i, j, k)));
    return r;
  }

  bool startPointLeaf(const PointDataTree::LeafNodeType& leaf) {
    // The arrays are read directly: an AttributeHandle per point leaf and destination leaf
    // cost a heap allocation each (a tenth of the rasterization).
    mP = &static_cast<const PositionAttribute&>(leaf.constAttributeArray(mIndex[0]));
    mR = &static_cast<const FloatAttribute&>(leaf.constAttributeArray(mIndex[1]));
    mT = &static_cast<const FloatAttribute&>(leaf.constAttributeArray(mIndex[2]));
    mRadius = &static_cast<const FloatAttribute&>(leaf.constAttributeArray(mIndex[3]));
    mU = mIndex[4] == openvdb::points::AttributeSet::INVALID_POS
             ? nullptr
             : &static_cast<const PositionAttribute&>(leaf.constAttributeArray(mIndex[4]));
    return true;
  }
  bool endPointLeaf(const PointDataTree::LeafNodeType&) { return true; }
  bool finalize(const Coord&, std::size_t) { return true; }

  void rasterizePoint(const Coord& ijk, const Index id, const CoordBBox& bounds) {
    // P is the point's offset from the centre of voxel ijk, in voxels ([-0.5, 0.5]).
    const openvdb::Vec3f p = mP->getUnsafe(id);
    const float radius = mRadius->getUnsafe(id);
    // Most points a leaf visits lie in its search margin and miss it: reject them before
    // building their kernels.
    const Coord reach(int(std::ceil(radius)));
    if (!bounds.hasOverlap(CoordBBox(ijk - reach, ijk + reach))) return;
    const Tent tx(p.x(), radius), ty(p.y(), radius), tz(p.z(), radius);
    CoordBBox box(ijk + Coord(tx.lo, ty.lo, tz.lo), ijk + Coord(tx.hi, ty.hi, tz.hi));
    box.intersect(bounds);
    if (box.empty()) return;
    float* density = this->buffer<0>();
    float* weight = this->buffer<1>();
    float* heat = this->buffer<2>();
    openvdb::Vec3s* momentum = mU ? this->buffer<3>() : nullptr;
    const auto& mask = *this->mask<0>();
    const float t = mT->getUnsafe(id) - mAmbient;
    const float r = mR->getUnsafe(id) / (tx.sum * ty.sum * tz.sum);  // R_p / S, so Σ_v w = 1
    const openvdb::Vec3s u = mU ? mU->getUnsafe(id) : openvdb::Vec3s(0.f);
    for (Coord c = box.min(); c.x() <= box.max().x(); ++c.x()) {
      const float kx = tx.k[c.x() - ijk.x() - tx.lo];
      const Index i = (Index(c.x()) & (DIM - 1u)) << 2 * LOG2DIM;
      for (c.y() = box.min().y(); c.y() <= box.max().y(); ++c.y()) {
        const float kxy = kx * ty.k[c.y() - ijk.y() - ty.lo];
        const Index ij = i + ((Index(c.y()) & (DIM - 1u)) << LOG2DIM);
        for (c.z() = box.min().z(); c.z() <= box.max().z(); ++c.z()) {
          const Index offset = ij + (Index(c.z()) & (DIM - 1u));
          if (!mask.isOn(offset)) continue;
          const float k = kxy * tz.k[c.z() - ijk.z() - tz.lo];
          density[offset] += k * r;
          weight[offset] += k;
          heat[offset] += k * t;
          if (momentum) momentum[offset] += k * u;
        }
      }
    }
  }

 private:
  float mAmbient;
  std::array<std::size_t, 5> mIndex;
  const openvdb::Int32Tree* mRanges;
  const PositionAttribute* mP = nullptr;
  const FloatAttribute* mR = nullptr;
  const FloatAttribute* mT = nullptr;
  const FloatAttribute* mRadius = nullptr;
  const PositionAttribute* mU = nullptr;
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
  if (!(spacingScale >= 0.f) || !std::isfinite(spacingScale))
    throw std::invalid_argument("spacing_scale must be >= 0 (0: the trilinear hat; got " +
                                std::to_string(spacingScale) + ")");
  if (!(maxSplatRadius >= 1.f && maxSplatRadius <= 8.f))
    throw std::invalid_argument("max_splat_radius must be in [1, 8] voxels (got " +
                                std::to_string(maxSplatRadius) + ")");
  if (!(sheetInterval >= 0.f) || !std::isfinite(sheetInterval))
    throw std::invalid_argument("sheet_interval must be >= 0 s (got " + std::to_string(sheetInterval) + ")");
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

    if (view.velocities) {
      pts::appendAttribute<openvdb::Vec3f>(tree, "velocity");
      pts::populateAttribute(tree, index->tree(), "velocity", Vec3Points<openvdb::Vec3f>{view.velocities, view.count});
    }
    // r_p from the local spacing (fields/splat_radius.h), and ceil(max r_p) per point leaf.
    const std::vector<int> leafRange =
        appendSplatRadius(tree, {params.spacingScale, params.maxSplatRadius, params.sheetInterval, h}, "radius");

    // Every voxel a kernel touches: the point voxels of each leaf dilated by its ceil(max r_p).
    openvdb::tree::LeafManager<PointDataTree> pointLeaves(tree);
    openvdb::Int32Tree ranges(1);
    int largest = 1;
    for (int r : leafRange) largest = std::max(largest, r);
    std::vector<openvdb::MaskTree> reach(std::size_t(largest) + 1);
    for (std::size_t n = 0; n < pointLeaves.leafCount(); ++n) {
      const auto& leaf = pointLeaves.leaf(n);
      ranges.setValue(leaf.origin() >> FireTransfer::LOG2DIM, leafRange[n]);
      auto* m = reach[std::size_t(leafRange[n])].touchLeaf(leaf.origin());
      m->setValueMask(m->getValueMask() | leaf.getValueMask());
    }
    for (int r = 1; r <= largest; ++r) {
      if (reach[std::size_t(r)].empty()) continue;
      openvdb::tools::dilateActiveValues(reach[std::size_t(r)], r, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                         openvdb::tools::EXPAND_TILES);
      density->topologyUnion(reach[std::size_t(r)]);
    }
    FloatTree weight(*density, 0.f, openvdb::TopologyCopy());
    FloatTree heat(*density, 0.f, openvdb::TopologyCopy());
    if (view.velocities)
      velocity = std::make_shared<openvdb::Vec3STree>(*density, openvdb::Vec3s(0.f), openvdb::TopologyCopy());
    openvdb::Vec3STree none(openvdb::Vec3s(0.f));  // no leaves: no momentum sums
    const auto& descriptor = tree.cbeginLeaf()->attributeSet().descriptor();
    FireTransfer transfer(*density, weight, heat, velocity ? *velocity : none, ambient,
                          {descriptor.find("P"), descriptor.find("density"), descriptor.find("temperature"),
                           descriptor.find("radius"), descriptor.find("velocity")},
                          ranges);
    pts::rasterize(*points, transfer);

    // Per voxel: mass per volume, mean temperature, flame, mean velocity.
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
      auto* u = velocity ? velocity->probeLeaf(o) : nullptr;
      for (auto it = leaf.beginValueOn(); it; ++it) {
        const Index m = it.pos();
        const float sumW = w->getValue(m);
        if (sumW <= 0.f) {
          // Touched by no particle's kernel (a zero weight at the dilation's rim).
          leaf.setValueOff(m, 0.f);
          t->setValueOff(m, ambient);
          f->setValueOff(m, 0.f);
          if (u) u->setValueOff(m, openvdb::Vec3s(0.f));
          continue;
        }
        it.setValue(it.getValue() * massScale);
        const float tv = ambient + q->getValue(m) / (sumW > 1.f ? sumW : 1.f);
        t->setValueOnly(m, tv);
        const float fv = (tv - ignition) / span;
        f->setValueOnly(m, fv < 0.f ? 0.f : (fv > 1.f ? 1.f : fv));
        if (u) u->setValueOnly(m, u->getValue(m) / sumW);
      }
    });
    openvdb::tools::pruneInactive(*density);
    openvdb::tools::pruneInactive(*temperature);
    openvdb::tools::pruneInactive(*flame);
    if (velocity) openvdb::tools::pruneInactive(*velocity);
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
