/// \file vdb_grids.cpp
/// Dense arrays to sparse OpenVDB grids (zero voxels skipped) and the atomic VDB file write.

#include "io/vdb_grids.h"

#include "io/vdb_guard.h"

#include <openvdb/io/File.h>
#include <openvdb/tools/Dense.h>

#include "io/byte_buffer.h"

#include <cerrno>
#include <cstdio>
#include <mutex>
#include <stdexcept>

namespace plume {
namespace {

openvdb::CoordBBox cellBox(glm::ivec3 n) {
  return openvdb::CoordBBox(openvdb::Coord(0, 0, 0), openvdb::Coord(n.x - 1, n.y - 1, n.z - 1));
}

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error("VDB file '" + path + "': " + what);
}

}  // namespace

void initializeOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

openvdb::math::Transform::Ptr cellCenteredTransform(float cellSize, glm::vec3 origin) {
  auto xform = openvdb::math::Transform::createLinearTransform(double(cellSize));
  xform->postTranslate(openvdb::Vec3d(double(origin.x) + 0.5 * double(cellSize),
                                      double(origin.y) + 0.5 * double(cellSize),
                                      double(origin.z) + 0.5 * double(cellSize)));
  return xform;
}

openvdb::FloatGrid::Ptr denseFloatGrid(const std::string& name, const float* values, glm::ivec3 n,
                                       const openvdb::math::Transform::Ptr& xform) {
  auto grid = openvdb::FloatGrid::create(/*background=*/0.f);
  // Dense only reads here; it wants a mutable pointer because it can also be written to.
  // copyFromDense converts leaf-sized blocks in parallel (TBB).
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(cellBox(n),
                                                                const_cast<float*>(values));
  openvdb::tools::copyFromDense(dense, *grid, /*tolerance=*/0.f);
  grid->setName(name);
  grid->setTransform(xform);
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  return grid;
}

openvdb::Vec3SGrid::Ptr denseVectorGrid(const std::string& name, const openvdb::Vec3s* values,
                                        glm::ivec3 n, const openvdb::math::Transform::Ptr& xform) {
  auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
  openvdb::tools::Dense<openvdb::Vec3s, openvdb::tools::LayoutXYZ> dense(
      cellBox(n), const_cast<openvdb::Vec3s*>(values));
  openvdb::tools::copyFromDense(dense, *grid, /*tolerance=*/openvdb::Vec3s(0.f));
  grid->setName(name);
  grid->setTransform(xform);
  grid->setGridClass(openvdb::GRID_UNKNOWN);
  grid->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
  return grid;
}

void writeGridsAtomic(const std::string& path, const openvdb::GridPtrVec& grids,
                      const openvdb::MetaMap& meta) {
  initializeOpenVdb();
  const std::string tmp = path + ".tmp";
  int err = 0;  // errno after OpenVDB's own stream wrote the file
  try {
    {
      openvdb::io::File file(tmp);
      if (openvdb::io::File::hasBloscCompression())
        file.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
      errno = 0;
      file.write(grids, meta);
      file.close();
      err = errno;
    }
    // io::File::write does not report a failed stream: a write(2) that failed for want of room
    // left its errno; anything else (a short file) is caught by reading the header and grid
    // descriptors back through the same checks as every read (vdb_guard).
    if (err == ENOSPC || err == EDQUOT || err == EFBIG || err == EIO)
      throw std::runtime_error(writeFailure(err));
    std::string damage = "grids missing after writing";
    bool complete = false;
    try {
      complete = CheckedVdbFile(tmp).gridNames().size() == grids.size();
    } catch (const std::exception& e) {
      damage = e.what();
    }
    if (!complete) {
      // A short file whose stream left no errno (libc++'s, in the portable build, does not):
      // a file at the size limit or a full disk still says so, not "damaged".
      const int cause = writeFailureCause(tmp, 0);
      throw std::runtime_error(cause != 0 ? writeFailure(cause) : damage);
    }
  } catch (const std::exception& e) {
    std::remove(tmp.c_str());  // no half file: the previous one, if any, stays
    fail(path, std::string("cannot be written: ") + e.what());
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    fail(path, "cannot rename the temporary file '" + tmp + "' to it");
  }
}

}  // namespace plume
