/// \file convert.cpp
/// The shared conversions of convert.h that are more than a few lines: vectors, grids, meshes,
/// streak snapshot dicts and flame dicts between NumPy and the core.

#include "bindings/convert.h"

#include <pybind11/stl.h>

#include <sstream>

namespace plume::bindings {

std::string shapeText(const py::array& a) {
  std::ostringstream s;
  s << "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s << (d ? ", " : "") << a.shape(d);
  s << (a.ndim() == 1 ? ",)" : ")");
  return s.str();
}

// --- small vectors ------------------------------------------------------------------------

glm::dvec3 dvec3Arg(const py::handle& o, const char* name, Vec3Form form) {
  if (form == Vec3Form::Array) {
    const DoubleArrayC a = DoubleArrayC::ensure(o);
    if (!a || a.size() != 3) throw py::value_error(std::string(name) + " must be 3 numbers");
    return {a.data()[0], a.data()[1], a.data()[2]};
  }
  if (form == Vec3Form::Sequence) {
    if (!py::isinstance<py::sequence>(o) || py::len(o) != 3)
      throw py::value_error(std::string(name) + " must be a sequence of 3 numbers");
    const py::sequence s = py::reinterpret_borrow<py::sequence>(o);
    return {s[0].cast<double>(), s[1].cast<double>(), s[2].cast<double>()};
  }
  const auto v = o.cast<std::vector<double>>();
  if (v.size() != 3) throw py::value_error(std::string(name) + " must hold 3 numbers");
  return {v[0], v[1], v[2]};
}

glm::ivec3 ivec3Arg(const py::handle& o, const char* name, long long lo, long long hi, const char* range) {
  if (!py::isinstance<py::sequence>(o) || py::len(o) != 3)
    throw py::value_error(std::string(name) + " must be a sequence of 3 integers");
  const py::sequence s = py::reinterpret_borrow<py::sequence>(o);
  glm::ivec3 r;
  for (int a = 0; a < 3; ++a) {
    const long long v = s[std::size_t(a)].cast<long long>();
    if (v < lo || v > hi) throw py::value_error(std::string(name) + " must be " + range);
    r[a] = int(v);
  }
  return r;
}

// --- grids ----------------------------------------------------------------------------------

py::tuple macArrays(const MacGrid3& v) {
  return py::make_tuple(gridArray(v.u()), gridArray(v.v()), gridArray(v.w()));
}

void checkGridShape(const py::array& a, glm::ivec3 n, const std::string& name) {
  if (a.ndim() != 3 || a.shape(0) != n.x || a.shape(1) != n.y || a.shape(2) != n.z) {
    std::ostringstream s;
    s << name << " must have shape (" << n.x << ", " << n.y << ", " << n.z << "), got "
      << shapeText(a);
    throw py::value_error(s.str());
  }
}

void copyGrid(const FloatArrayF& a, glm::ivec3 n, ScalarGrid& g, const std::string& name) {
  checkGridShape(a, n, name);
  g.resize(n);
  std::memcpy(g.data(), a.data(), g.count() * sizeof(float));
}

VectorGrid vectorGridOf(const FloatArrayF& a) {
  VectorGrid g(glm::ivec3(int(a.shape(0)), int(a.shape(1)), int(a.shape(2))));
  const auto r = a.unchecked<4>();
  for (py::ssize_t k = 0; k < a.shape(2); ++k)
    for (py::ssize_t j = 0; j < a.shape(1); ++j)
      for (py::ssize_t i = 0; i < a.shape(0); ++i)
        g(int(i), int(j), int(k)) = {r(i, j, k, 0), r(i, j, k, 1), r(i, j, k, 2)};
  return g;
}

void copyMac(const py::handle& uvw, glm::ivec3 cells, MacGrid3& mac, const char* name) {
  if (!py::isinstance<py::sequence>(uvw) || py::len(uvw) != 3)
    throw py::value_error(std::string(name) + " must be a tuple (u, v, w)");
  const py::sequence s = py::reinterpret_borrow<py::sequence>(uvw);
  mac.resize(cells);
  static const char* kComponent[3] = {"u", "v", "w"};
  for (int a = 0; a < 3; ++a) {
    glm::ivec3 size = cells;
    size[a] += 1;
    const std::string what = std::string(name) + " " + kComponent[a];
    copyGrid(ensureArray<FloatArrayF>(s[std::size_t(a)], what), size, mac.component(a), what);
  }
}

// --- points, integers, matrices, meshes -------------------------------------------------------

std::vector<glm::vec3> pointsArg(const FloatArrayC& a, const char* name) {
  if (a.size() == 0) return {};
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(std::string(name) + " must have shape (N, 3), got " + shapeText(a));
  std::vector<glm::vec3> p(std::size_t(a.shape(0)));
  std::memcpy(p.data(), a.data(), p.size() * sizeof(glm::vec3));
  return p;
}

std::vector<int> intsArg(const Int64ArrayC& a, const char* name) {
  if (a.size() == 0) return {};
  if (a.ndim() != 1)
    throw py::value_error(std::string(name) + " must be one-dimensional, got " + shapeText(a));
  std::vector<int> v(std::size_t(a.shape(0)));
  for (std::size_t n = 0; n < v.size(); ++n) {
    const long long x = a.data()[n];
    if (x < -2147483648LL || x > 2147483647LL)
      throw py::value_error(std::string(name) + " holds " + std::to_string(x) + ", outside int32");
    v[n] = int(x);
  }
  return v;
}

std::vector<int> toIntVector(const py::object& values, const std::string& name) {
  return intsArg(ensureArray<Int64ArrayC>(values, name), name.c_str());
}

glm::mat4 matrixArg(const DoubleArrayC& a, const char* name) {
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw py::value_error(std::string(name) + " must be a 4x4 matrix, got shape " + shapeText(a));
  glm::mat4 m;
  // numpy.array(obj.matrix_world) is row-major (world = M @ [x, y, z, 1]); glm is column-major.
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) m[col][row] = float(a.data()[row * 4 + col]);
  return m;
}

EmitterMesh emitterMeshArg(const FloatArrayC& vertices, const Int64ArrayC& triangles,
                           const DoubleArrayC& matrix, const DoubleArrayC& matrixNext,
                           const std::string& name) {
  EmitterMesh mesh;
  mesh.name = name;
  if (vertices.size() != 0 && (vertices.ndim() != 2 || vertices.shape(1) != 3))
    throw py::value_error("vertices of '" + name + "' must have shape (N, 3), got " +
                          shapeText(vertices));
  if (triangles.size() != 0 && (triangles.ndim() != 2 || triangles.shape(1) != 3))
    throw py::value_error("triangles of '" + name + "' must have shape (M, 3), got " +
                          shapeText(triangles));
  mesh.vertices = pointsArg(vertices, "vertices");
  const std::size_t nv = mesh.vertices.size();
  const std::size_t nt = triangles.size() == 0 ? 0 : std::size_t(triangles.shape(0));
  mesh.triangles.resize(nt);
  const long long* t = triangles.data();
  for (std::size_t n = 0; n < nt * 3; ++n) {
    if (t[n] < 0 || t[n] >= (long long)nv)
      throw py::value_error("triangles of '" + name + "' index vertex " + std::to_string(t[n]) +
                            ", outside [0, " + std::to_string(nv) + ")");
    mesh.triangles[n / 3][int(n % 3)] = int(t[n]);
  }
  mesh.matrix = matrixArg(matrix, "matrix");
  mesh.matrixNext = matrixArg(matrixNext, "matrix_next");
  return mesh;
}

// --- streak snapshots -----------------------------------------------------------------------

StreakFrame streakFrameArg(const py::handle& obj, bool needDensity, const std::string& what,
                           bool positionsOnly) {
  if (!py::isinstance<py::dict>(obj))
    throw py::value_error(what + " must be a dict with counts, positions, density");
  const py::dict d = py::reinterpret_borrow<py::dict>(obj);
  auto get = [&](const char* key, bool required) -> py::object {
    if (d.contains(key)) return d[key];
    if (required) throw py::value_error(what + " has no '" + key + "'");
    return py::none();
  };
  StreakFrame f;
  f.counts = intsArg(ensureArray<Int64ArrayC>(get("counts", true), what + ": counts"), "counts");
  f.positions =
      pointsArg(ensureArray<FloatArrayC>(get("positions", true), what + ": positions"), "positions");
  const std::size_t m = f.positions.size();
  const py::object groups = get("groups", false);
  const auto groupsOf = [&] {
    return groups.is_none() ? std::vector<int>(f.counts.size(), 0)
                            : intsArg(ensureArray<Int64ArrayC>(groups, what + ": groups"), "groups");
  };
  if (positionsOnly) {
    f.groups = groupsOf();
    std::size_t total = 0;
    for (int c : f.counts) {
      if (c < 0) throw py::value_error(what + ": counts hold " + std::to_string(c) + " (negative)");
      total += std::size_t(c);
    }
    if (f.groups.size() != f.counts.size())
      throw py::value_error(what + ": " + std::to_string(f.groups.size()) + " groups for " +
                            std::to_string(f.counts.size()) + " sources");
    if (m != total)
      throw py::value_error(what + ": counts sum to " + std::to_string(total) +
                            " particles but there are " + std::to_string(m) + " positions");
    return f;
  }
  const py::object density = get("density", needDensity);
  if (density.is_none()) {
    f.density.assign(m, 0.f);
  } else {
    const FloatArrayC a = ensureArray<FloatArrayC>(density, what + ": density");
    if (a.ndim() != 1) throw py::value_error(what + ": density must be one-dimensional");
    f.density.assign(a.data(), a.data() + a.size());
  }
  f.groups = groupsOf();
  const py::object outside = get("outside", false);
  if (outside.is_none()) {
    f.outside.assign(m, 0);
  } else {
    const UInt8ArrayC a = ensureArray<UInt8ArrayC>(outside, what + ": outside");
    if (a.ndim() != 1) throw py::value_error(what + ": outside must be one-dimensional");
    f.outside.assign(a.data(), a.data() + a.size());
    for (std::uint8_t& o : f.outside) o = o ? 1 : 0;
  }
  f.validate();  // std::invalid_argument -> ValueError
  return f;
}

std::vector<StreakFrame> toStreakFrames(const py::sequence& snapshots, bool positionsOnly) {
  std::vector<StreakFrame> out;
  out.reserve(std::size_t(py::len(snapshots)));
  for (std::size_t t = 0; t < std::size_t(py::len(snapshots)); ++t)
    out.push_back(streakFrameArg(snapshots[t], false, "snapshot " + std::to_string(t), positionsOnly));
  return out;
}

py::dict streakFrameDict(const StreakFrame& f) {
  py::dict d;
  d["counts"] = array1DAs<std::int32_t>(f.counts);
  d["positions"] = rowsArray(f.positions);
  d["density"] = array1DAs<float>(f.density);
  d["groups"] = array1DAs<std::int32_t>(f.groups);
  d["outside"] = array1DAs<bool>(f.outside);
  return d;
}

// --- flame dicts ---------------------------------------------------------------------------

DoubleArrayC doubleRowsArg(const py::handle& o, py::ssize_t k, const char* what) {
  const DoubleArrayC a = DoubleArrayC::ensure(o);
  if (!a || a.ndim() != 2 || a.shape(1) != k)
    throw py::value_error(std::string(what) + " must be an array of shape (N, " + std::to_string(k) + ")");
  return a;
}

Flame flameArg(const py::handle& h, std::size_t index) {
  const py::dict d = py::reinterpret_borrow<py::dict>(h);
  const std::string name = "flames[" + std::to_string(index) + "]";
  if (!d.contains("points")) throw py::value_error(name + " needs 'points'");
  const DoubleArrayC x = doubleRowsArg(d["points"], 3, (name + ".points").c_str());
  const py::ssize_t n = x.shape(0);
  Flame f;
  f.points.resize(std::size_t(n));
  for (py::ssize_t k = 0; k < n; ++k) f.points[std::size_t(k)].x = {x.at(k, 0), x.at(k, 1), x.at(k, 2)};
  if (d.contains("velocities")) {
    const DoubleArrayC v = doubleRowsArg(d["velocities"], 3, (name + ".velocities").c_str());
    if (v.shape(0) != n) throw py::value_error(name + ".velocities must have one row per point");
    for (py::ssize_t k = 0; k < n; ++k) f.points[std::size_t(k)].v = {v.at(k, 0), v.at(k, 1), v.at(k, 2)};
  }
  if (d.contains("ages")) {
    const DoubleArrayC a = DoubleArrayC::ensure(d["ages"]);
    if (!a || a.ndim() != 1 || a.shape(0) != n) throw py::value_error(name + ".ages must have shape (N,)");
    for (py::ssize_t k = 0; k < n; ++k) f.points[std::size_t(k)].age = a.at(k);
  }
  f.radius = d.contains("radius") ? d["radius"].cast<double>() : 0.0;
  if (d.contains("intensity")) f.intensity = d["intensity"].cast<double>();
  if (d.contains("temperature")) f.temperature = d["temperature"].cast<double>();
  if (d.contains("brightness")) f.brightness = d["brightness"].cast<double>();
  if (d.contains("age")) f.age = d["age"].cast<double>();
  if (d.contains("lifespan")) f.lifespan = d["lifespan"].cast<double>();
  f.id = d.contains("id") ? d["id"].cast<std::uint32_t>() : std::uint32_t(index + 1);
  if (d.contains("source")) f.source = d["source"].cast<int>();
  if (d.contains("separated")) f.separated = d["separated"].cast<bool>();
  if (d.contains("split_length")) f.splitLength = d["split_length"].cast<double>();
  return f;
}

py::dict flameDict(const Flame& f) {
  std::vector<glm::dvec3> x, v;
  py::array_t<double> ages(py::ssize_t(f.points.size()));
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    x.push_back(f.points[i].x);
    v.push_back(f.points[i].v);
    ages.mutable_data()[i] = f.points[i].age;
  }
  py::dict d;
  d["id"] = f.id;
  d["source"] = f.source;
  d["separated"] = f.separated;
  d["split_length"] = f.splitLength;
  d["age"] = f.age;
  d["lifespan"] = f.lifespan;
  d["radius"] = f.radius;
  d["intensity"] = f.intensity;
  d["temperature"] = f.temperature;
  d["brightness"] = f.brightness;
  d["points"] = rowsArray(x);
  d["velocities"] = rowsArray(v);
  d["ages"] = ages;
  return d;
}

}  // namespace plume::bindings
