/// \file flowgraph_cost_stream_test.cpp
/// The cost matrix of eq. 9-10 and the weights α, β ([Graph Fire Synthesis] §4.3) streamed
/// from pathline files: the same bits as with every group in memory, at 1 and 2 threads and
/// any block size; each group read once as a row and once per row block before it as a column.

#include "flowgraph/cost_matrix.h"
#include "flowgraph/cost_matrix_stream.h"
#include "flowgraph/cost_tiles.h"
#include "flowgraph/magnitude_weights.h"
#include "flowgraph/node_files.h"
#include "tests/flowgraph_group_files.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include "tests/temp_path.h"

namespace plume {
namespace {

using testing::filePointers;
using testing::openFiles;
using testing::oscillatingGroups;
using testing::pointers;
using testing::writeOscillatingFiles;

/// 113 nodes in three states (4 tiles of 32 per side, the last partial); 37 particles and 19
/// samples exercise every tail of the kernel.
const std::vector<int> kCounts = {45, 38, 30};
constexpr int kParticles = 37, kSamples = 19;

std::string prefix(const std::string& name) { return plume::test::tempPath("cost_stream_" + name + "_"); }

FlowGraphParams params(int threads) {
  FlowGraphParams p;
  p.alpha = 0.7;
  p.beta = 1.3;
  p.threads = threads;
  return p;
}

/// Row blocks of `rowNodes` groups of `nodes`, column blocks of `columnNodes`.
CostStreamParams blocks(const NodeFiles& nodes, int rowNodes, int columnNodes) {
  CostStreamParams s;
  s.rowBlockBytes = std::size_t(rowNodes) * nodes.groupBytes();
  s.columnNodes = columnNodes;
  return s;
}

/// The groups read back from the files, in node order (what the add-on held before).
std::vector<PathlineGroup> readAll(const NodeFiles& nodes) {
  std::vector<PathlineGroup> g(std::size_t(nodes.size()));
  nodes.read(0, g);
  return g;
}

TEST(FlowGraphCostStream, SameBitsAsInMemoryAtOneAndTwoThreadsAndAnyBlock) {
  for (bool half : {false, true}) {
    const auto paths = writeOscillatingFiles(prefix(half ? "f16" : "f32"), kCounts, kParticles, kSamples, 5,
                                             0.05f, half);
    const auto files = openFiles(paths);
    const NodeFiles nodes(filePointers(files));
    ASSERT_EQ(nodes.size(), 113);
    EXPECT_EQ(nodes.counts(), kCounts);
    const auto groups = readAll(nodes);
    if (!half) {  // a float32 file holds the generated groups exactly
      const auto made = oscillatingGroups(kCounts, kParticles, kSamples, 5);
      EXPECT_EQ(groups[77].temperature, made[77].temperature);
    }
    const CostMatrix memory = computeCostMatrix(pointers(groups), params(1));
    for (int threads : {1, 2})
      for (const auto& [rows, cols] : {std::pair{32, 32}, std::pair{64, 32}, std::pair{32, 96}, std::pair{512, 64}}) {
        CostStreamStats stats;
        const CostMatrix streamed = computeCostMatrix(nodes, params(threads), nullptr, blocks(nodes, rows, cols), &stats);
        EXPECT_EQ(streamed.values(), memory.values()) << "float16 " << half << ", " << threads << " threads, rows "
                                                      << rows << ", columns " << cols;
        EXPECT_EQ(stats.rowNodes, std::min(rows, 128));  // never more tiles than the matrix has
        EXPECT_EQ(stats.columnNodes, cols);
      }
    for (const std::string& p : paths) std::remove(p.c_str());
  }
}

TEST(FlowGraphCostStream, ReadsEachGroupOnceAsRowAndOncePerEarlierRowBlock) {
  const auto paths = writeOscillatingFiles(prefix("reads"), kCounts, 4, 3, 6);
  const auto files = openFiles(paths);
  const NodeFiles nodes(filePointers(files));
  CostStreamStats stats;
  computeCostMatrix(nodes, params(2), nullptr, blocks(nodes, 32, 32), &stats);
  // Row blocks start at 0, 32, 64, 96: the columns after them are 81 + 49 + 17 + 0 groups.
  EXPECT_EQ(stats.rowNodes, 32);
  EXPECT_EQ(stats.groupReads, 113 + 81 + 49 + 17);
  computeCostMatrix(nodes, params(2), nullptr, blocks(nodes, 64, 32), &stats);
  EXPECT_EQ(stats.groupReads, 113 + 49);
  for (const std::string& p : paths) std::remove(p.c_str());
}

TEST(FlowGraphCostStream, SameWeightsBitForBit) {
  const auto paths = writeOscillatingFiles(prefix("weights"), {50, 40}, kParticles, kSamples, 7);
  const auto files = openFiles(paths);
  const NodeFiles nodes(filePointers(files));  // 90 nodes: three batches of kWeightBatch, the last partial
  const auto groups = readAll(nodes);
  const FlowWeights memory = sameMagnitudeWeights(pointers(groups), 1);
  for (int threads : {1, 2}) {
    const FlowWeights streamed = sameMagnitudeWeights(nodes, threads);
    EXPECT_EQ(streamed.alpha, memory.alpha);
    EXPECT_EQ(streamed.beta, memory.beta);
    const FlowWeights again = sameMagnitudeWeights(pointers(groups), threads);
    EXPECT_EQ(again.alpha, memory.alpha);
  }
  for (const std::string& p : paths) std::remove(p.c_str());
}

TEST(FlowGraphCostStream, ProgressCountsTheInMemoryTilesAndCancels) {
  const auto paths = writeOscillatingFiles(prefix("progress"), kCounts, 4, 3, 8);
  const auto files = openFiles(paths);
  const NodeFiles nodes(filePointers(files));
  CostMatrixProgress done;
  EXPECT_EQ(computeCostMatrix(nodes, params(2), &done, blocks(nodes, 32, 64)).size(), 113);
  EXPECT_EQ(done.tiles.load(), costTileCount(113));
  EXPECT_EQ(done.tiles.load(), 10);  // 4 × 4 tiles of 32, upper triangle
  EXPECT_EQ(done.tilesDone.load(), 10);
  CostMatrixProgress cancelled;
  cancelled.cancel = true;
  CostStreamStats stats;
  EXPECT_EQ(computeCostMatrix(nodes, params(2), &cancelled, blocks(nodes, 32, 64), &stats).size(), 0);
  EXPECT_EQ(cancelled.tilesDone.load(), 0);
  EXPECT_EQ(stats.groupReads, 0);  // nothing read once cancelled
  for (const std::string& p : paths) std::remove(p.c_str());
}

TEST(FlowGraphCostStream, RejectsStatesThatDoNotShareALayoutAndBadSettings) {
  const auto a = writeOscillatingFiles(prefix("layout_a"), {3}, 8, 6, 9);
  const auto b = writeOscillatingFiles(prefix("layout_b"), {3}, 7, 6, 9);
  const auto files = openFiles({a[0], b[0]});
  try {
    NodeFiles nodes(filePointers(files));
    ADD_FAILURE() << "no exception for states of 8 and 7 particles";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("state 1 has 7 particles per group, state 0 has 8"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(NodeFiles({}), std::invalid_argument);
  EXPECT_THROW(NodeFiles({nullptr}), std::invalid_argument);
  const auto one = openFiles(a);
  const NodeFiles nodes(filePointers(one));
  FlowGraphParams bad = params(1);
  bad.alpha = -1.0;
  EXPECT_THROW(computeCostMatrix(nodes, bad), std::invalid_argument);
  CostStreamParams noColumns;
  noColumns.columnNodes = 0;
  EXPECT_THROW(computeCostMatrix(nodes, params(1), nullptr, noColumns), std::invalid_argument);
  EXPECT_THROW(sameMagnitudeWeights(nodes, -1), std::invalid_argument);
  for (const std::string& p : a) std::remove(p.c_str());
  for (const std::string& p : b) std::remove(p.c_str());
}

}  // namespace
}  // namespace plume
