/// \file splat_radius.cpp
/// Per-particle splat radius from a coarse particle count (see splat_radius.h).

#include "fields/splat_radius.h"

#include <openvdb/points/AttributeArray.h>
#include <openvdb/points/PointAttribute.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>

namespace plume {
namespace {

using openvdb::Coord;
using openvdb::Index;
using openvdb::points::PointDataTree;

constexpr int kLog2Coarse = 2;                // C = 4 Δx
constexpr float kCoarse = 1 << kLog2Coarse;   // C, voxels
constexpr float kCoarseVolume = kCoarse * kCoarse * kCoarse;

}  // namespace

std::vector<int> appendSplatRadius(PointDataTree& tree, const SplatRadiusParams& params,
                                   const std::string& name, const std::string& velocity) {
  namespace pts = openvdb::points;
  pts::appendAttribute<float>(tree, name);
  openvdb::tree::LeafManager<PointDataTree> leaves(tree);
  std::vector<int> leafRange(leaves.leafCount(), 1);
  if (leaves.leafCount() == 0) return leafRange;

  // n_c: a point leaf (8³ voxels) holds exactly 2³ coarse cells; each task counts its own leaf.
  using Count = std::array<std::uint32_t, 8>;
  std::vector<Count> counts(leaves.leafCount());
  leaves.foreach([&](const PointDataTree::LeafNodeType& leaf, std::size_t n) {
    Count c{};
    Index begin = 0;
    for (Index m = 0; m < PointDataTree::LeafNodeType::SIZE; ++m) {
      const Index end = Index(leaf.getValue(m));
      if (end > begin) {
        const Coord ijk = PointDataTree::LeafNodeType::offsetToLocalCoord(m);
        c[((ijk.x() >> kLog2Coarse) << 2) | ((ijk.y() >> kLog2Coarse) << 1) | (ijk.z() >> kLog2Coarse)] += end - begin;
      }
      begin = end;
    }
    counts[n] = c;
  });
  openvdb::FloatTree coarse(0.f);  // coarse cell c at coordinate c (voxel >> 2)
  {
    openvdb::tree::ValueAccessor<openvdb::FloatTree> acc(coarse);
    for (std::size_t n = 0; n < counts.size(); ++n) {
      const Coord o = leaves.leaf(n).origin() >> kLog2Coarse;
      for (int a = 0; a < 8; ++a)
        if (counts[n][a] > 0) acc.setValue(o + Coord((a >> 2) & 1, (a >> 1) & 1, a & 1), float(counts[n][a]));
    }
  }

  const float kappa = params.spacingScale, rMax = std::max(1.f, params.maxRadius);
  const float sheet = kappa > 0.f ? params.sheetInterval / params.voxelSize : 0.f;  // Δt_n / Δx
  leaves.foreach([&](PointDataTree::LeafNodeType& leaf, std::size_t n) {
    const auto& descriptor = leaf.attributeSet().descriptor();
    pts::AttributeHandle<openvdb::Vec3f> position(leaf.constAttributeArray(descriptor.find("P")));
    pts::AttributeWriteHandle<float> radius(leaf.attributeArray(descriptor.find(name)));
    const std::size_t u = descriptor.find(velocity);
    std::unique_ptr<pts::AttributeHandle<openvdb::Vec3f>> speed;
    if (sheet > 0.f && u != pts::AttributeSet::INVALID_POS)
      speed = std::make_unique<pts::AttributeHandle<openvdb::Vec3f>>(leaf.constAttributeArray(u));
    openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(coarse);
    float largest = 1.f;
    for (auto voxel = leaf.beginValueOn(); voxel; ++voxel) {
      const Coord ijk = voxel.getCoord();
      for (auto id = leaf.beginIndexVoxel(ijk); id; ++id) {
        float r = 1.f;
        if (kappa > 0.f) {
          // Index position of the point in coarse cell-centre units: cell c's centre is at
          // voxel coordinate C c + (C - 1) / 2.
          const openvdb::Vec3f q = (ijk.asVec3s() + position.get(*id) - 0.5f * (kCoarse - 1.f)) / kCoarse;
          const Coord c0(int(std::floor(q.x())), int(std::floor(q.y())), int(std::floor(q.z())));
          const openvdb::Vec3f f = q - c0.asVec3s();
          float count = 0.f;
          for (int a = 0; a < 8; ++a) {
            const int dx = (a >> 2) & 1, dy = (a >> 1) & 1, dz = a & 1;
            const float w = (dx ? f.x() : 1.f - f.x()) * (dy ? f.y() : 1.f - f.y()) * (dz ? f.z() : 1.f - f.z());
            count += w * acc.getValue(c0 + Coord(dx, dy, dz));
          }
          const float spacing = count > 0.f ? std::cbrt(kCoarseVolume / count) : rMax;
          const float gap = speed ? speed->get(*id).length() * sheet : 0.f;
          r = std::min(rMax, std::max({1.f, kappa * spacing, gap}));
        }
        radius.set(*id, r);
        largest = std::max(largest, r);
      }
    }
    leafRange[n] = int(std::ceil(largest));
  });
  return leafRange;
}

}  // namespace plume
