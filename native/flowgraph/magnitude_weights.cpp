/// \file magnitude_weights.cpp
/// α, β of eq. 9 as ratios of the fields' variances over the groups (§4.3), accumulated batch
/// by batch in a fixed order so that groups in memory and groups streamed from files give the
/// same bits.

#include "flowgraph/magnitude_weights.h"

#include "core/parallel.h"
#include "flowgraph/flow_graph_params.h"
#include "flowgraph/state_nodes.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

/// Σ over groups g and elements e of (x_g,e − x̄_e)² for one field of `count` floats per group,
/// x̄ the mean group, fed in two passes of batches of groups (the groups in node order both
/// times). The elements are split in chunks of kChunk; each chunk sums its groups in order, and
/// the chunks' sums are added in chunk order: the result depends on neither the thread count
/// nor how the groups are batched.
class SquaredDeviations {
 public:
  explicit SquaredDeviations(std::size_t count)
      : mCount(count), mMean(count, 0.0), mPartial((count + kChunk - 1) / kChunk, 0.0) {}

  /// Pass 1: x̄ += x for every group of the batch.
  void addToMean(const std::vector<const float*>& batch) {
    forChunks([&](std::size_t e0, std::size_t n, std::size_t) {
      for (const float* x : batch)
        for (std::size_t e = e0; e < e0 + n; ++e) mMean[e] += x[e];
    });
  }
  /// Between the passes: x̄ /= the number of groups.
  void finishMean(std::size_t groups) {
    const double inv = 1.0 / double(groups);
    for (double& m : mMean) m *= inv;
  }
  /// Pass 2: Σ (x − x̄)² for every group of the batch.
  void addDeviations(const std::vector<const float*>& batch) {
    forChunks([&](std::size_t e0, std::size_t n, std::size_t c) {
      double sum = mPartial[c];
      for (const float* x : batch)
        for (std::size_t e = e0; e < e0 + n; ++e) sum += (x[e] - mMean[e]) * (x[e] - mMean[e]);
      mPartial[c] = sum;
    });
  }
  double sum() const {
    double s = 0.0;
    for (double p : mPartial) s += p;
    return s;
  }

 private:
  static constexpr std::size_t kChunk = 4096;
  template <typename Body>
  void forChunks(const Body& body) {
    parallelFor(0, int(mPartial.size()), [&](int c) {
      const std::size_t e0 = std::size_t(c) * kChunk;
      body(e0, std::min(kChunk, mCount - e0), std::size_t(c));
    });
  }
  std::size_t mCount;
  std::vector<double> mMean, mPartial;
};

/// The three fields of a group as flat floats: velocity (3 per sample), density, temperature.
const float* field(const PathlineGroup& g, int f) {
  return f == 0 ? &g.velocity.front().x : f == 1 ? g.density.data() : g.temperature.data();
}

/// Receives one batch of groups.
using Batch = std::function<void(const std::vector<const PathlineGroup*>&)>;

/// The weights from the three fields' sums; visit(batch) calls batch() on every batch of groups
/// in node order, once per pass (means, then deviations).
FlowWeights weightsOf(std::size_t values, std::size_t groups, const std::function<void(const Batch&)>& visit) {
  SquaredDeviations sums[3] = {SquaredDeviations(3 * values), SquaredDeviations(values), SquaredDeviations(values)};
  std::vector<const float*> arrays;
  for (int pass = 0; pass < 2; ++pass) {
    visit([&](const std::vector<const PathlineGroup*>& batch) {
      for (int f = 0; f < 3; ++f) {
        arrays.clear();
        for (const PathlineGroup* g : batch) arrays.push_back(field(*g, f));
        if (pass == 0)
          sums[f].addToMean(arrays);
        else
          sums[f].addDeviations(arrays);
      }
    });
    if (pass == 0)
      for (SquaredDeviations& s : sums) s.finishMean(groups);
  }
  // The common factor Δt_n / (|Ω| N) of eq. 9-10 and of the mean cancels in the ratios.
  const double u = sums[0].sum(), r = sums[1].sum(), t = sums[2].sum();
  const double reference = u > 0.0 ? u : 1.0;
  auto ratio = [&](double v) {
    const double q = reference / v;
    return v > 0.0 && std::isfinite(q) ? q : 1.0;
  };
  FlowWeights w;
  w.alpha = ratio(r);
  w.beta = ratio(t);
  return w;
}

void requireThreads(int threads) {
  if (threads < 0 || threads > kMaxFlowGraphThreads)
    throw std::invalid_argument("threads must be in [0, " + std::to_string(kMaxFlowGraphThreads) +
                                "] (0 = all cores) (got " + std::to_string(threads) + ")");
}

}  // namespace

FlowWeights sameMagnitudeWeights(const std::vector<const PathlineGroup*>& groups, int threads) {
  stateNodeCounts(groups);  // one layout, arrays of its size
  requireThreads(threads);
  ThreadLimit limit(threads);
  return weightsOf(groups.front()->layout.values(), groups.size(),
                   [&](const Batch& batch) { batch(groups); });
}

FlowWeights sameMagnitudeWeights(const NodeFiles& nodes, int threads) {
  requireThreads(threads);
  ThreadLimit limit(threads);
  std::vector<PathlineGroup> groups;
  std::vector<const PathlineGroup*> batch;
  return weightsOf(nodes.layout().values(), std::size_t(nodes.size()),
                   [&](const Batch& visit) {
                     for (int first = 0; first < nodes.size(); first += kWeightBatch) {
                       groups.resize(std::size_t(std::min(kWeightBatch, nodes.size() - first)));
                       nodes.read(first, groups);
                       batch.clear();
                       for (const PathlineGroup& g : groups) batch.push_back(&g);
                       visit(batch);
                     }
                   });
}

}  // namespace plume
