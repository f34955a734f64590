/// \file bind_streak_clusters.cpp
/// Clustering of streaklines for Python ([Smoke Surfaces] §3.3): shared frames, the sparse
/// distances h of a candidate group, the default threshold h0, clusters, the Figure 4 counts and
/// the greedy order. Conversions and docstrings only; long calls release the GIL.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "streak/clustering.h"

#include <pybind11/stl.h>

#include <memory>

namespace py = pybind11;

namespace plume::bindings {
namespace {

/// Frames converted once and shared by the distances of every group (counts and positions).
struct PyStreakFrames {
  SharedStreakFrames frames;
};

/// A StreakFrames object, or a sequence of snapshot dicts converted now.
SharedStreakFrames sharedFrames(const py::object& frames) {
  if (py::isinstance<PyStreakFrames>(frames)) return frames.cast<const PyStreakFrames&>().frames;
  if (!py::isinstance<py::sequence>(frames))
    throw py::value_error("frames must be a StreakFrames or a sequence of snapshot dicts");
  return std::make_shared<const std::vector<StreakFrame>>(
      toStreakFrames(py::reinterpret_borrow<py::sequence>(frames), /*positionsOnly=*/true));
}

/// The held pairs (a < b) as three arrays, sorted by (a, b).
py::tuple pairsToNumpy(const StreakDistances& d) {
  std::vector<int> a, b;
  std::vector<double> h;
  a.reserve(d.pairCount());
  b.reserve(d.pairCount());
  h.reserve(d.pairCount());
  for (int m = 0; m < d.size(); ++m)
    for (int i = 0; i < d.degree(m); ++i)
      if (d.neighbours(m)[i] > m) {
        a.push_back(m);
        b.push_back(d.neighbours(m)[i]);
        h.push_back(d.neighbourDistances(m)[i]);
      }
  return py::make_tuple(array1DAs<std::int32_t>(a), array1DAs<std::int32_t>(b), array1DAs<double>(h));
}

void checkMember(const StreakDistances& d, int a) {
  if (a < 0 || a >= d.size())
    throw py::index_error("member " + std::to_string(a) + " is not in h (size " +
                          std::to_string(d.size()) + ")");
}

void bindDistances(py::module_& m) {
  py::class_<PyStreakFrames>(
      m, "StreakFrames",
      "Streak snapshots (dicts as read_streak_file() gives them) converted once: counts, "
      "positions and groups, shared by the distances of every candidate group (§3.3).")
      .def(py::init([](const py::sequence& snapshots) {
             return PyStreakFrames{std::make_shared<const std::vector<StreakFrame>>(
                 toStreakFrames(snapshots, /*positionsOnly=*/true))};
           }),
           py::arg("snapshots"), "ValueError on inconsistent sizes (naming the snapshot).")
      .def("__len__", [](const PyStreakFrames& f) { return f.frames->size(); })
      .def_property_readonly(
          "source_count",
          [](const PyStreakFrames& f) {
            return f.frames->empty() ? 0 : f.frames->back().sourceCount();
          },
          "Point sources of the last snapshot.");

  py::class_<StreakDistances> c(
      m, "StreakDistances",
      "smoke_surfaces §3.3: the distances h(α,β) = Σ_t [Σ_i |p(α,t,i) − p(β,t,i)|²] / N(t) of one "
      "candidate group, sparse: every pair with h < reach, exactly (bit for bit the value a "
      "brute force over all pairs computes), and no other. Clusters, counts and the curve are "
      "exact for every h0 <= reach; greedy orders are exact always (h beyond the reach is "
      "computed on demand). Members are 0..size-1, in the order of the source IDs given.");
  c.def("__len__", &StreakDistances::size);
  c.def_property_readonly("size", &StreakDistances::size, "Members (sources) of the group.");
  c.def_property_readonly("reach", &StreakDistances::reach,
                          "Every pair with h < reach is held (inf: all pairs).");
  c.def_property_readonly("mean", &StreakDistances::meanDistance,
                          "§3.3 default h0: the mean of h over the pairs α < β (from centred sums, "
                          "without the pairs). ValueError for fewer than 2 members.");
  c.def_property_readonly("pair_count", &StreakDistances::pairCount, "Pairs held (h < reach).");
  c.def("pairs", &pairsToNumpy,
        "The held pairs as (a int32 (P,), b int32 (P,), h float64 (P,)), a < b, sorted by (a, b).");
  c.def(
      "distance",
      [](const StreakDistances& d, int a, int b) {
        checkMember(d, a);
        checkMember(d, b);
        return d.distance(a, b);
      },
      py::arg("a"), py::arg("b"), "h(a, b) of any two members, computed now (0 for a == b).");
  c.def(
      "curve",
      [](const StreakDistances& d) {
        std::vector<int> surfaces, lines;
        for (const ClusterSummary& s : d.curve().counts) {
          surfaces.push_back(s.surfaces);
          lines.push_back(s.streaklines);
        }
        return py::make_tuple(array1DAs<double>(d.curve().values), array1DAs<std::int32_t>(surfaces),
                              array1DAs<std::int32_t>(lines));
      },
      "Figure 4 as steps: (values float64 (K,), surfaces int32 (K,), streaklines int32 (K,)). "
      "For values[k] < h0 <= values[k+1] (and h0 <= reach) the threshold h0 gives surfaces[k] "
      "surfaces from streaklines[k] streaklines; below values[0], none. Single linkage over the "
      "held pairs sorted by h (Kruskal), so exact for every h0 <= reach.");
  c.def_property_readonly(
      "stats",
      [](const StreakDistances& d) {
        py::dict s;
        s["examined"] = d.stats().examined;
        s["exact"] = d.stats().exact;
        s["kept"] = d.stats().kept;
        return s;
      },
      "Work of the pair search: pairs examined (neighbouring grid cells), pairs whose h was "
      "computed (the bound did not rule them out), pairs kept.");
  c.def(
      "with_reach",
      [](const StreakDistances& d, double reach) {
        py::gil_scoped_release release;
        return d.withReach(reach);
      },
      py::arg("reach"),
      "The same group's distances holding every pair with h < reach (>= 0 or inf), reusing "
      "the mean and the pruning directions. Releases the GIL.");

  m.def(
      "streak_distances",
      [](const py::object& frames, const py::object& sourceIds, double reach, int rank) {
        SharedStreakFrames shared = sharedFrames(frames);
        std::vector<int> ids = toIntVector(sourceIds, "source_ids");
        DistanceParams params;
        params.reach = reach;
        params.projection.rank = rank;
        py::gil_scoped_release release;
        return StreakDistances(StreakGroup(std::move(shared), std::move(ids)), params);
      },
      py::arg("frames"), py::arg("source_ids"), py::arg("reach") = -1.0,
      py::arg("projection_rank") = ProjectionParams{}.rank,
      "smoke_surfaces §3.3: the StreakDistances of the sources source_ids (member a is "
      "source_ids[a]) over frames (a StreakFrames, or a sequence of snapshot dicts), frames with "
      "N(t) = 0 skipped. reach < 0 (default): the group's default h0, the mean of h. Pairs are "
      "found through a grid over the group's leading principal directions (projection_rank of "
      "them, 0..64; speed only, never results). Releases the GIL. ValueError on an ID out of "
      "range, unequal counts N(t), or a default reach for fewer than 2 sources.");
  m.def("default_threshold", &defaultThreshold, py::arg("h"),
        "§3.3: default h0, the mean of h over pairs α < β (ValueError if n < 2).");
  m.def(
      "cluster_sources",
      [](const StreakDistances& h, double h0) {
        py::gil_scoped_release release;
        return clusterSources(h, h0);
      },
      py::arg("h"), py::arg("h0"),
      "§3.3: clusters of members joined (transitively) by h < h0, each of >= 2 members, as "
      "sorted lists of member indices. Exact for 0 <= h0 <= h.reach; ValueError otherwise.");
  m.def(
      "cluster_summary",
      [](const StreakDistances& h, double h0) {
        const ClusterSummary s = clusterSummary(h, h0);
        return py::make_tuple(s.surfaces, s.streaklines);
      },
      py::arg("h"), py::arg("h0"),
      "(surfaces, streaklines) that threshold h0 gives (Figure 4), from h.curve() in "
      "O(log pairs): cheap enough for live UI. Exact for 0 <= h0 <= h.reach; ValueError "
      "otherwise.");
  m.def(
      "order_greedy",
      [](const StreakDistances& h, const py::object& members) {
        const std::vector<int> ms = toIntVector(members, "members");
        py::gil_scoped_release release;
        return orderGreedy(h, ms);
      },
      py::arg("h"), py::arg("members"),
      "§3.3 Figure 5: greedy minimum-length order of a cluster's members (member indices), the "
      "same as over all pairs; h beyond the reach is computed when needed. Releases the GIL.");
  m.def(
      "build_surfaces",
      [](const py::sequence& snapshots, const py::object& groups, double h0) {
        const std::vector<StreakFrame> frames = toStreakFrames(snapshots, /*positionsOnly=*/true);
        std::vector<int> g;
        if (!groups.is_none()) g = toIntVector(groups, "groups");
        std::vector<StreakSurface> surfaces;
        {
          py::gil_scoped_release release;
          surfaces = buildSurfaces(frames, g, h0);
        }
        py::list out;
        for (const StreakSurface& s : surfaces) {
          py::dict d;
          d["group"] = s.group;
          d["threshold"] = s.threshold;
          d["sources"] = s.sources;
          out.append(d);
        }
        return out;
      },
      py::arg("snapshots"), py::arg("groups") = py::none(), py::arg("h0") = -1.0,
      "§3.3 end to end: per candidate group (groups: one per source, None = the last snapshot's), "
      "distances, threshold (h0 >= 0, or < 0 for the group's mean), clusters and greedy order. "
      "List of dict(group, threshold, sources = ordered source IDs). ValueError when a group has "
      "a single point source.");
}

}  // namespace

void bindStreakClusters(py::module_& m) { bindDistances(m); }

}  // namespace plume::bindings
