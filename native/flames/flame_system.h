#pragma once
/// \file flame_system.h
/// The structure of structural flames over time ([Structural Flames] §4.1–4.3, §6.1–6.2):
/// sources release particles into the wind every step, spines evolve by eq. 1, are fitted and
/// re-sampled, break by the statistical process of §4.3, separated pieces die after A·i³, and
/// control points are pushed out of obstacles. Deterministic for a seed at any thread count:
/// every flame draws from its own stream Rng(seed, id), ids are given in a fixed order, and flames
/// are processed independently in parallel then merged in order.

#include "core/rng.h"
#include "flames/breakaway.h"
#include "flames/flame.h"
#include "flames/flame_params.h"
#include "flames/obstacle_sdf.h"
#include "flames/spine_noise.h"
#include "flames/wind.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace plume {

/// Counters since construction, for the checks of §4.3 (rate f, mean life A/4).
struct FlameStatistics {
  double eligibleTime = 0.0;            ///< flame-seconds with length > H_i (breakaway tests run)
  std::uint64_t breakaways = 0;         ///< statistical breakaways (Poisson, rate f on eligible time)
  std::uint64_t forcedBreakaways = 0;   ///< breaks because length > H_max (D = 1)
  std::uint64_t separatedBorn = 0;      ///< pieces split off, plus flames detached at a source's end
  std::uint64_t separatedDied = 0;      ///< separated flames removed at the end of their life
  double lifespanSum = 0.0;             ///< Σ A·i³ over the flames that died
  double ageAtDeathSum = 0.0;           ///< Σ age reached by them (in [A·i³, A·i³ + dt))
};

/// Flames from a set of sources (§4.1–4.3).
class FlameSystem {
 public:
  /// Throws std::invalid_argument for bad params (FlameParams::validate()).
  FlameSystem(const FlameParams& params, std::uint64_t seed);

  /// Adds a source (validated, std::invalid_argument naming sources[i]); returns its index.
  int addSource(const FlameSource& source);
  /// Replaces source i (animation). A change of position moves its attached flame rigidly with it
  /// at the next step: attached flames live in the source's frame (§4.2), where the air passes at −V.
  void setSource(int index, const FlameSource& source);
  const std::vector<FlameSource>& sources() const { return mSources; }

  /// Replaces the settings (keyable); throws std::invalid_argument and keeps the old ones if bad.
  /// A change of the spine noise's settings rebuilds its field (same seed).
  void setParams(const FlameParams& params);
  const FlameParams& params() const { return mParams; }
  /// v_K of eq. 1 (§4.2): the Kolmogorov velocity field of this system's seed.
  const SpineNoise& spineNoise() const { return *mSpineNoise; }

  /// w of eq. 1: the fields added here are summed.
  CompositeWind& wind() { return mWind; }
  const CompositeWind& wind() const { return mWind; }
  /// Obstacles of §6.1 (control points are kept outside them).
  ObstacleSet& obstacles() { return mObstacles; }

  /// Advances time by dt (s, finite > 0), in these stages:
  ///  1. sources: a source past its end time releases its flame as a separated one (lifespan A·i³);
  ///     a source active at t with no flame starts one with a single particle (§4.1, §6.2);
  ///  2. per flame, in parallel: attached flames follow their source's displacement; every point
  ///     moves by eq. 1 (V_p = −V for attached flames; v_K read from one shared field); attached flames get a new particle at the
  ///     source and are fitted and re-sampled to n points (first and last kept), separated ones to
  ///     their own count; the breakaway process may split off the top; points are pushed out of
  ///     obstacles (all but an attached flame's base, which is the source);
  ///  3. in flame order: new pieces are appended with the next ids, statistics gathered, separated
  ///     flames whose age reached their lifespan removed.
  void step(double dt);
  /// Time of the flames (s): the sum of the steps.
  double time() const { return mTime; }

  /// Every live flame, attached ones and separated pieces, in a deterministic order.
  const std::vector<Flame>& flames() const { return mFlames; }
  /// H_p, H_i, H_max of a flame (its source's height scale applied).
  FlameHeights heights(const Flame& flame) const;
  const FlameStatistics& statistics() const { return mStats; }

 private:
  struct FlameState {
    Rng rng;
    double budget = 0.0;  // eligible seconds left before the next statistical breakaway
  };
  /// What processing one flame produced in a step (merged in order in stage 3).
  struct FlameOutcome {
    BreakawayDecision decision;
    bool hasPiece = false;
    Flame piece;
    double pieceLifespan = 0.0;
  };

  void updateSources();
  void startFlame(int source);
  void processFlame(std::size_t index, double dt, FlameOutcome& out);
  void mergeOutcomes(std::vector<FlameOutcome>& outcomes, double dt);
  void appendFlame(Flame flame);

  FlameParams mParams;
  std::uint64_t mSeed;
  double mTime = 0.0;
  std::uint32_t mNextId = 0;
  std::vector<FlameSource> mSources;
  std::vector<glm::dvec3> mLastPosition;  // source positions at the previous step
  std::vector<glm::dvec3> mDisplacement;  // source displacement during the current step
  std::vector<Flame> mFlames;
  std::vector<FlameState> mStates;  // aligned with mFlames
  CompositeWind mWind;
  std::shared_ptr<const SpineNoise> mSpineNoise;  // v_K, rebuilt when its settings change
  ObstacleSet mObstacles;
  FlameStatistics mStats;
};

}  // namespace plume
