#pragma once
/// \file flame_shape.h
/// The shape and render stage of structural flames for one frame ([Structural Flames]
/// §4.4–4.5, §5): for every flame, Monte-Carlo samples of eq. 4 in its profile, the buoyancy
/// flow noise, the cylindrical mapping of Figure 4, the Kolmogorov noise, merging, base colour
/// and incandescence (eq. 5–6), and one light per flame.
///
/// Deterministic: particle n of flame f draws from Rng(seed, f.id · 2³² + n), flames are laid
/// out in input order and merging keeps that order, so the result is bit-identical at any
/// thread count.

#include "flames/blackbody.h"
#include "flames/flame.h"
#include "flames/flame_sampler.h"
#include "flames/flow_noise.h"
#include "flames/incandescence.h"
#include "flames/kolmogorov_noise.h"
#include "flames/obstacle_sdf.h"
#include "flames/profile_density.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace plume {

/// Every setting of the shape stage.
struct FlameShapeParams {
  DensityParams density;
  SamplingParams sampling;
  FlowNoiseParams flowNoise;
  KolmogorovParams kolmogorov;
  IncandescenceParams incandescence;
  double width = 1.0;    ///< the flame's widest radius R = width · Flame::radius
  double temperature = 1500.0;  ///< K at d = I: the blackbody base colour of a flame without a colour image
  bool merging = true;   ///< §4.5 (the paper switched it off for the dragon)
  /// A of §4.3 (s): a separated piece's colour moves to its profile's tip colour as its gas ages,
  /// by e^(−t_p / A) of each particle's age t_p since it left the burning surface, and its E
  /// fades by e^(−mean t_p / A) (0: off).
  double coolingTime = 0.0;
  std::uint64_t seed = 0;
  int threads = 0;       ///< 0: all cores
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// The particles of one frame, every array of size().
struct FlameParticles {
  std::vector<glm::vec3> positions;   ///< world, m
  std::vector<glm::vec3> velocities;  ///< m/s, eq. 1 of the nearest spine points (motion blur)
  /// Base colour (§5.1) as a chromaticity: the colour image (or blackbody) scaled per flame so
  /// that the power-weighted mean luminance of its particles is 1 (the image sets the colour and
  /// the relative brightness across the flame, eq. 5–6 the flame's brightness).
  std::vector<glm::vec3> colors;
  std::vector<float> density;         ///< d(x_i) = I / (1 + dist²/ℓ²), eq. 4
  std::vector<float> incandescence;   ///< E_i, eq. 6: W/m² at the camera
  /// P_i = E_i · 4π((h/2)² + l²) = E d(x_i) / (n ⟨d⟩), W: the particle's share of eq. 5's E. A
  /// volume renderer does eq. 6's projection to the camera itself, so the grids hold this.
  std::vector<float> power;
  std::vector<float> mass;            ///< ∫ d dV of its flame / n (m³): rasterized density ≈ d
  std::vector<std::uint32_t> flame;   ///< index of its flame in the input
  std::size_t size() const { return positions.size(); }
  void resize(std::size_t n);
};

/// One frame's output.
struct FlameShapeFrame {
  FlameParticles particles;
  std::vector<FlameLight> lights;  ///< one per flame, input order
  std::vector<int> sampled;        ///< samples drawn per flame (before merging)
  std::vector<double> energy;      ///< eq. 5 times the intensity, per flame
  std::size_t merged = 0;          ///< particles dropped by merging
  std::size_t obstructed = 0;      ///< particles dropped inside obstacles (§6.1)
};

/// The shape stage, built once per bake (profile tables, noise tile), run once per frame.
class FlameShaper {
 public:
  /// `profiles`: flame f uses profiles[min(f.source, size-1)]; `images`: none (blackbody), one for
  /// all, or one per profile; an empty (0 × 0) image: the blackbody of T · d_i/I. Throws std::invalid_argument on bad settings.
  FlameShaper(const std::vector<FlameProfile>& profiles, const FlameShapeParams& params,
              std::vector<ColorImage> images = {});
  /// The frame at time t (s) seen from `camera`.
  FlameShapeFrame shape(const std::vector<Flame>& flames, double time, const FlameCamera& camera) const;
  /// The same into `out`, reusing its arrays' memory (a bake's frame loop).
  void shape(const std::vector<Flame>& flames, double time, const FlameCamera& camera, FlameShapeFrame& out) const;

  /// §6.1: particles whose final position is inside an obstacle (φ < 0) are dropped; none
  /// (the default) keeps all. Read from several threads during shape().
  void setObstacles(std::shared_ptr<const ObstacleSet> obstacles) { mObstacles = std::move(obstacles); }

  const ProfileDensity& density(int source) const;
  const FlameShapeParams& params() const { return mParams; }
  const FlowNoise& flowNoise() const { return mFlow; }
  const KolmogorovNoise& kolmogorov() const { return *mKolmogorov; }

 private:
  int profileIndex(const Flame& flame) const;
  FlameShapeParams mParams;
  std::vector<std::unique_ptr<ProfileDensity>> mDensities;
  std::vector<ColorImage> mImages;
  FlowNoise mFlow;
  std::unique_ptr<KolmogorovNoise> mKolmogorov;
  std::unique_ptr<BlackbodyRamp> mBlackbody;  ///< colours of flames without an image
  std::shared_ptr<const ObstacleSet> mObstacles;
};

}  // namespace plume
