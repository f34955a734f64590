#pragma once
/// \file cost_matrix.h
/// The transition cost matrix C = (c_ij) of a flow graph ([Graph Fire Synthesis] §4.3,
/// eq. 9-10) between every pair of nodes of every state: all groups of all states in one matrix,
/// ordered state by state and chronologically inside a state (stateNodeCounts()).

#include "flowgraph/flow_graph_params.h"
#include "flowgraph/pathline_group.h"

#include <atomic>
#include <cstddef>
#include <vector>

namespace plume {

/// C of §4.3: N×N, symmetric, zero diagonal, row-major doubles.
class CostMatrix {
 public:
  CostMatrix() = default;
  /// An N×N matrix of zeros.
  explicit CostMatrix(int size);
  /// A matrix from N×N row-major values (e.g. a cached one). Throws std::invalid_argument unless
  /// there are N² values, all finite and >= 0, symmetric bit for bit, with a zero diagonal.
  static CostMatrix fromValues(int size, std::vector<double> values);

  /// N, the number of nodes.
  int size() const { return mSize; }
  /// c_ij of eq. 9.
  double operator()(int i, int j) const { return mValues[index(i, j)]; }
  /// All N² values, row-major.
  const std::vector<double>& values() const { return mValues; }
  /// Sets c_ij and c_ji (the matrix stays symmetric).
  void set(int i, int j, double c) { mValues[index(i, j)] = mValues[index(j, i)] = c; }

 private:
  std::size_t index(int i, int j) const { return std::size_t(i) * std::size_t(mSize) + std::size_t(j); }
  int mSize = 0;
  std::vector<double> mValues;
};

/// Progress and cancellation of computeCostMatrix(), shared with a caller on another thread
/// (a bake's worker thread computes, the UI polls fraction() and may set cancel).
struct CostMatrixProgress {
  std::atomic<bool> cancel{false};  ///< set to stop early: computeCostMatrix() then returns a 0×0 matrix
  std::atomic<int> tilesDone{0};    ///< tiles of node pairs finished
  std::atomic<int> tiles{0};        ///< tiles in all (set when the computation starts)
  /// Finished fraction in [0, 1].
  double fraction() const {
    const int t = tiles.load();
    return t > 0 ? double(tilesDone.load()) / t : 0.0;
  }
};

/// Eq. 9-10 over the whole lifetime for every pair of groups:
///   c_ij = sqrt( Σ_s Δt_n [ ‖U_i − U_j‖² + α ‖R_i − R_j‖² + β ‖T_i − T_j‖² ] ),
///   ‖U_i − U_j‖² = (1/|Ω|) Σ_x |u_i(x, s) − u_j(x, s)|²  (likewise R, T),
/// the time integral of eq. 9 taken by the rectangle rule over the L samples s Δt_n,
/// s = 0 .. L−1 (t_max = L Δt_n). Groups must be ordered state by state (stateNodeCounts(),
/// whose errors it throws, e.g. for states of different particle counts). Uses params.alpha,
/// beta and threads; the values are the same bit for bit at any thread count and on any
/// instruction set (see cost_matrix.cpp for the blocking and the accumulation). `progress`
/// (optional) is updated as tiles finish and checked for cancellation. Every group must be in
/// memory: for groups in the states' pathline files, computeCostMatrix(NodeFiles) of
/// cost_matrix_stream.h holds a bounded number of them and gives the same bits.
CostMatrix computeCostMatrix(const std::vector<const PathlineGroup*>& groups, const FlowGraphParams& params,
                             CostMatrixProgress* progress = nullptr);

}  // namespace plume
