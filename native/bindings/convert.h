#pragma once
/// \file convert.h
/// The conversions every binding file shares, defined once: NumPy argument types, small vectors
/// to and from Python, the shape text of error messages, copies of vectors and grids into NumPy
/// arrays, path arguments with the GIL released, and the argument structures more than one
/// component takes or gives (meshes as SmokeSolver.add_source takes them, face velocities,
/// streak snapshot dicts, flame dicts). Messages name the argument so a script can tell which one was wrong.

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "flames/flame.h"
#include "solver/emitters.h"
#include "tracers/streak_frame.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <glm/glm.hpp>

#include <array>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

namespace plume::bindings {

namespace py = pybind11;

// --- NumPy argument types: element type, then memory order (C: last index fastest; F:
// first index fastest, the order of Grid3). Other arrays and sequences are converted.

using FloatArrayC = py::array_t<float, py::array::c_style | py::array::forcecast>;
using FloatArrayF = py::array_t<float, py::array::f_style | py::array::forcecast>;
using DoubleArrayC = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Int32ArrayC = py::array_t<int, py::array::c_style | py::array::forcecast>;
using Int64ArrayC = py::array_t<long long, py::array::c_style | py::array::forcecast>;
using UInt8ArrayC = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>;

/// "(4, 3)", "(5,)": an array's shape as Python prints it, for error messages.
std::string shapeText(const py::array& a);

/// An object as a NumPy array of A's type; ValueError "<name> must be a numeric array" if it
/// cannot be converted.
template <typename A>
A ensureArray(const py::handle& o, const std::string& name) {
  A a = A::ensure(o);
  if (!a) {
    PyErr_Clear();
    throw py::value_error(name + " must be a numeric array");
  }
  return a;
}

// --- small vectors ------------------------------------------------------------------------

/// How a vector argument is checked, each the way its arguments always have been (scripts see
/// the same errors).
enum class Vec3Form {
  /// ValueError "<name> must hold 3 numbers" unless a sequence of 3 numbers (another kind of
  /// object: pybind11's cast error).
  Numbers,
  /// ValueError "<name> must be a sequence of 3 numbers" unless a sequence of length 3.
  Sequence,
  /// ValueError "<name> must be 3 numbers" unless NumPy makes an array of 3 numbers of it.
  Array,
};

/// Three numbers as a glm vector, checked as `form` says.
glm::dvec3 dvec3Arg(const py::handle& o, const char* name, Vec3Form form = Vec3Form::Numbers);

/// dvec3Arg() in single precision.
inline glm::vec3 vec3Arg(const py::handle& o, const char* name, Vec3Form form = Vec3Form::Numbers) {
  return glm::vec3(dvec3Arg(o, name, form));
}

/// A sequence of 3 integers each in [lo, hi]; ValueError "<name> must be a sequence of 3
/// integers", or "<name> must be <range>" for a value outside [lo, hi].
glm::ivec3 ivec3Arg(const py::handle& o, const char* name, long long lo, long long hi, const char* range);

/// std::array (pybind11's conversion of a 3-sequence) as a glm vector.
inline glm::vec3 vec3Of(const std::array<float, 3>& v) { return {v[0], v[1], v[2]}; }
inline glm::ivec3 ivec3Of(const std::array<int, 3>& v) { return {v[0], v[1], v[2]}; }

/// (x, y, z) as a Python tuple of the vector's component type.
template <typename V>
py::tuple vec3Tuple(const V& v) {
  return py::make_tuple(v.x, v.y, v.z);
}

// --- copies into NumPy arrays -------------------------------------------------------------

/// A copy of v as a 1-D array of the same type.
template <typename T>
py::array_t<T> array1D(const std::vector<T>& v) {
  py::array_t<T> a(py::ssize_t(v.size()));
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
  return a;
}

/// A copy of v as a 1-D array of T, element by element (int to int32, uint8 to bool, ...).
template <typename T, typename S>
py::array_t<T> array1DAs(const std::vector<S>& v) {
  py::array_t<T> a(py::ssize_t(v.size()));
  for (std::size_t n = 0; n < v.size(); ++n) a.mutable_data()[n] = T(v[n]);
  return a;
}

/// A 1-D array of n values fn(0), ..., fn(n - 1) as T.
template <typename T, typename Fn>
py::array_t<T> arrayFrom(std::size_t n, const Fn& fn) {
  py::array_t<T> a(static_cast<py::ssize_t>(n));
  for (std::size_t i = 0; i < n; ++i) a.mutable_data()[i] = T(fn(i));
  return a;
}

/// glm vectors (vec3, dvec3, vec4, ivec4, ...) as an (N, components) array of their type.
template <typename V>
py::array_t<typename V::value_type> rowsArray(const std::vector<V>& v) {
  using T = typename V::value_type;
  constexpr py::ssize_t k = V::length();
  static_assert(sizeof(V) == k * sizeof(T), "packed glm vectors");
  py::array_t<T> a({py::ssize_t(v.size()), k});
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(V));
  return a;
}

/// A copy of a grid as an (nx, ny, nz) Fortran-ordered array indexed [i, j, k] (Grid3 stores x
/// fastest, so the copy is one memcpy).
template <typename T>
py::array_t<T> gridArray(const Grid3<T>& g) {
  const glm::ivec3 n = g.size();
  py::array_t<T, py::array::f_style> a({py::ssize_t(n.x), py::ssize_t(n.y), py::ssize_t(n.z)});
  std::memcpy(a.mutable_data(), g.data(), sizeof(T) * g.count());
  return a;
}

/// The three face grids (u, v, w) as a tuple of gridArray() copies.
py::tuple macArrays(const MacGrid3& v);

// --- arrays into the core's types ---------------------------------------------------------

/// ValueError "<name> must have shape (nx, ny, nz), got <shape>" unless a is (n.x, n.y, n.z).
void checkGridShape(const py::array& a, glm::ivec3 n, const std::string& name);

/// A checked (n.x, n.y, n.z) array copied into g (resized to n).
void copyGrid(const FloatArrayF& a, glm::ivec3 n, ScalarGrid& g, const std::string& name);

/// An (nx, ny, nz, 3) array as a cell-centred vector grid (the caller checks the shape).
VectorGrid vectorGridOf(const FloatArrayF& a);

/// (u, v, w) face arrays, as SmokeSolver.get_velocity() returns them, into a MAC grid of
/// `cells`; ValueError naming "<name> u" and so on.
void copyMac(const py::handle& uvw, glm::ivec3 cells, MacGrid3& mac, const char* name);

/// An (N, 3) float array as points; an empty array gives no points. ValueError "<name> must
/// have shape (N, 3), got <shape>".
std::vector<glm::vec3> pointsArg(const FloatArrayC& a, const char* name);

/// A 1-D integer array as ints (ValueError naming it outside int32); an empty array gives none.
std::vector<int> intsArg(const Int64ArrayC& a, const char* name);

/// Any integer array-like as ints (intsArg() after ensureArray()).
std::vector<int> toIntVector(const py::object& values, const std::string& name);

/// A row-major 4x4 matrix (numpy.array(obj.matrix_world)) as glm's column-major one.
glm::mat4 matrixArg(const DoubleArrayC& a, const char* name);

/// A mesh as SmokeSolver.add_source() takes it: vertices (N, 3) object-local, triangles (M, 3),
/// 4x4 row-major matrices at frames f and f+1. ValueError naming the object.
EmitterMesh emitterMeshArg(const FloatArrayC& vertices, const Int64ArrayC& triangles,
                           const DoubleArrayC& matrix, const DoubleArrayC& matrixNext,
                           const std::string& name);

// --- streak snapshots (StreakTracer.snapshot(), read_streak_file()) --------------------------

/// A snapshot-like dict as a StreakFrame. counts and positions are required; density too when
/// `needDensity`; groups and outside default to zeros. With `positionsOnly`, density and outside
/// are neither read nor filled (empty), for code that reads counts, positions and groups only.
StreakFrame streakFrameArg(const py::handle& obj, bool needDensity, const std::string& what,
                           bool positionsOnly = false);

/// Every snapshot of a sequence ("snapshot t" in errors, ValueError on inconsistent sizes). With
/// positionsOnly, density and outside are neither read nor kept (left empty), for the clustering
/// of smoke_surfaces §3.3, which reads counts, positions and groups only.
std::vector<StreakFrame> toStreakFrames(const py::sequence& snapshots, bool positionsOnly);

/// A StreakFrame as the snapshot dict: counts (S,) int32, positions (M, 3) float32, density (M,)
/// float32, groups (S,) int32, outside (M,) bool.
py::dict streakFrameDict(const StreakFrame& f);

// --- flame dicts (FlameSystem.flames(), FlameShaper.shape()) --------------------------------

/// An (N, k) float64 array; ValueError "<what> must be an array of shape (N, k)" otherwise.
DoubleArrayC doubleRowsArg(const py::handle& o, py::ssize_t k, const char* what);

/// flames[index] as a Flame: points (N, 3) base to tip required; velocities (N, 3), ages (N,),
/// radius, intensity, temperature, id (default index + 1), source, separated optional.
/// ValueError naming "flames[index].<key>".
Flame flameArg(const py::handle& h, std::size_t index);

/// A flame as a dict: id, source, separated, age, lifespan, radius, intensity, temperature,
/// points (n, 3), velocities (n, 3), ages (n,) (float64).
py::dict flameDict(const Flame& f);

// --- paths ----------------------------------------------------------------------------------

/// A path argument given as str or os.PathLike, as a std::string (needs the GIL).
inline std::string pathArg(const py::handle& path) {
  return py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
}

/// fn(path) with the GIL released (file reads and writes), for a path given as str or
/// os.PathLike; returns what fn returns (a C++ value: no Python object is touched without the GIL).
template <typename Fn>
auto withPath(const py::handle& path, const Fn& fn) {
  const std::string p = pathArg(path);
  py::gil_scoped_release release;
  return fn(p);
}

}  // namespace plume::bindings
