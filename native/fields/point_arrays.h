#pragma once
/// \file point_arrays.h
/// glm::vec3 arrays as OpenVDB's point converters read them (the PointAttributeVector
/// interface of points::createPointDataGrid and points::populateAttribute): positions (getPos,
/// ValueT = Vec3R) or a Vec3f attribute (get). Shared by every rasterization of particles.

#include <openvdb/openvdb.h>

#include <glm/glm.hpp>

#include <cstddef>

namespace plume {

template <typename ValueT>
struct Vec3Points {
  using PosType = ValueT;
  using value_type = ValueT;
  const glm::vec3* data;
  std::size_t count;
  std::size_t size() const { return count; }
  void getPos(std::size_t n, ValueT& xyz) const { get(xyz, n); }
  void get(ValueT& value, std::size_t n) const { value = ValueT(data[n].x, data[n].y, data[n].z); }
  void get(ValueT& value, std::size_t n, openvdb::Index) const { get(value, n); }
};

}  // namespace plume
