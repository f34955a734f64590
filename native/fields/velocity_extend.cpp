/// \file velocity_extend.cpp
/// Coarse rasterization, then layer-by-layer dilation with neighbour means.

#include "fields/velocity_extend.h"

#include "fields/point_arrays.h"
#include "io/vdb_grids.h"

#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/points/PointRasterizeTrilinear.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <algorithm>
#include <cmath>

namespace plume {

openvdb::Vec3SGrid::Ptr extendedVelocity(const std::vector<glm::vec3>& positions,
                                         const std::vector<glm::vec3>& velocities,
                                         const VelocityExtendParams& params) {
  initializeOpenVdb();
  const auto xform = cellCenteredTransform(params.voxelSize, params.origin);
  openvdb::Vec3STree::Ptr tree;
  if (!positions.empty()) {
    namespace pts = openvdb::points;
    const Vec3Points<openvdb::Vec3R> at{positions.data(), positions.size()};
    auto index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(at, *xform);
    auto points = pts::createPointDataGrid<pts::NullCodec, pts::PointDataGrid>(*index, at, *xform);
    pts::appendAttribute<openvdb::Vec3f>(points->tree(), "velocity");
    pts::populateAttribute(points->tree(), index->tree(), "velocity", Vec3Points<openvdb::Vec3f>{velocities.data(), velocities.size()});
    tree = pts::rasterizeTrilinear</*Staggered=*/false, openvdb::Vec3f>(points->tree(), "velocity");
    const int layers = std::min(params.maxLayers, int(std::ceil(params.reach / params.voxelSize)));
    for (int layer = 0; layer < layers; ++layer) {
      openvdb::BoolTree set(*tree, false, openvdb::TopologyCopy());
      openvdb::tools::dilateActiveValues(*tree, 1, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                         openvdb::tools::IGNORE_TILES);
      // The new voxels, in the tree's (deterministic) order, each the mean of the set ones.
      std::vector<std::pair<openvdb::Coord, openvdb::Vec3s>> fresh;
      openvdb::tree::ValueAccessor<const openvdb::BoolTree> isSet(set);
      openvdb::tree::ValueAccessor<const openvdb::Vec3STree> value(*tree);
      for (auto it = tree->cbeginValueOn(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        if (isSet.isValueOn(c)) continue;
        openvdb::Vec3s sum(0.f);
        int n = 0;
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const openvdb::Coord q = c.offsetBy(dx, dy, dz);
              if (isSet.isValueOn(q)) sum += value.getValue(q), ++n;
            }
        fresh.emplace_back(c, n > 0 ? sum / float(n) : openvdb::Vec3s(0.f));
      }
      for (const auto& [c, v] : fresh) tree->setValueOn(c, v);
    }
  }
  auto grid = tree ? openvdb::Vec3SGrid::create(tree) : openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
  grid->setName("velocity");
  grid->setTransform(xform);
  grid->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
  return grid;
}

}  // namespace plume
