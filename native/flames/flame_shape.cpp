/// \file flame_shape.cpp
/// One frame of the shape stage: per-flame set-up, per-particle transforms in parallel chunks,
/// merging, compaction in input order, lights.

#include "flames/flame_shape.h"

#include "core/huge_pages.h"
#include "core/parallel.h"
#include "flames/blackbody.h"
#include "flames/merging.h"
#include "flames/spine_mapping.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

constexpr int kChunk = 2048;  ///< particles per parallel task
constexpr double kPi = 3.14159265358979323846;

/// A run of particles of one flame.
struct Chunk {
  int flame, begin, end;
};

std::string flameName(std::size_t f) { return "flame " + std::to_string(f); }

void checkFlame(const Flame& flame, std::size_t f) {
  if (flame.points.size() < 2) throw std::invalid_argument(flameName(f) + " needs at least 2 spine points");
  if (!(flame.radius > 0.0) || !std::isfinite(flame.radius))
    throw std::invalid_argument(flameName(f) + ": radius must be a finite number > 0 m");
  if (!(flame.splitLength >= 0.0) || !std::isfinite(flame.splitLength))
    throw std::invalid_argument(flameName(f) + ": split_length must be a finite number >= 0 m");
  if (!(flame.intensity >= 0.0) || !std::isfinite(flame.intensity))
    throw std::invalid_argument(flameName(f) + ": intensity must be a finite number >= 0");
  if (!(flame.brightness > 0.0) || !std::isfinite(flame.brightness))
    throw std::invalid_argument(flameName(f) + ": brightness must be a finite number > 0");
  if (!(flame.age >= 0.0 && flame.lifespan >= 0.0) || !std::isfinite(flame.age + flame.lifespan))
    throw std::invalid_argument(flameName(f) + ": age and lifespan must be finite numbers >= 0 s");
  for (const SpinePoint& p : flame.points)
    if (!std::isfinite(p.x.x + p.x.y + p.x.z + p.v.x + p.v.y + p.v.z + p.age))
      throw std::invalid_argument(flameName(f) + ": spine points must be finite");
}

/// h / h_split of a separated piece of spine length `length` (1: attached, or unknown).
double pieceShare(const Flame& flame, double length) {
  return flame.separated && flame.splitLength > length ? length / flame.splitLength : 1.0;
}

/// The life a separated piece has left, 1 - age / (A i³) in [0, 1] (1: attached).
double lifeLeft(const Flame& flame) {
  if (!flame.separated || !(flame.lifespan > 0.0)) return 1.0;
  return std::clamp(1.0 - flame.age / flame.lifespan, 0.0, 1.0);
}

/// Smallest width factor of a dying piece: it thins to a wisp, never to nothing.
constexpr double kWispWidth = 0.05;

/// The profile's widest radius R of a flame of spine length `length`: width × r. A separated
/// piece keeps its parent's width only at birth and in proportion: R × √(h / h_split × life
/// left), so a piece a third of its flame's length is a slimmer flame of nearly the parent's
/// aspect, not a ball of the parent's width, and it thins as it fades (§4.3 gives pieces a
/// lifespan, not a look: "there's no good model for how long it will remain visible").
double shapeRadius(const FlameShapeParams& params, const Flame& flame, double length) {
  return params.width * flame.radius *
         std::sqrt(std::max(pieceShare(flame, length) * lifeLeft(flame), kWispWidth));
}

}  // namespace

void FlameShapeParams::validate() const {
  density.validate();
  sampling.validate();
  flowNoise.validate();
  kolmogorov.validate();
  incandescence.validate();
  if (!(width > 0.0 && width <= 1000.0))
    throw std::invalid_argument("width must be in (0, 1000] times the source radius (got " + std::to_string(width) + ")");
  if (!(temperature >= 500.0 && temperature <= 40000.0))
    throw std::invalid_argument("temperature must be in [500, 40000] K (got " + std::to_string(temperature) + ")");
  if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: all cores)");
  if (!(coolingTime >= 0.0 && coolingTime <= 1000.0))
    throw std::invalid_argument("cooling_time must be in [0, 1000] s (got " + std::to_string(coolingTime) + ")");
}

void FlameParticles::resize(std::size_t n) {
  // A dragon frame is ~80 MB: on huge pages its first touch is ~20× cheaper (core/huge_pages.h).
  reserveHugePages(positions, n);
  reserveHugePages(velocities, n);
  reserveHugePages(colors, n);
  reserveHugePages(density, n);
  reserveHugePages(incandescence, n);
  reserveHugePages(power, n);
  reserveHugePages(mass, n);
  reserveHugePages(flame, n);
  positions.resize(n);
  velocities.resize(n);
  colors.resize(n);
  density.resize(n);
  incandescence.resize(n);
  power.resize(n);
  mass.resize(n);
  flame.resize(n);
}

FlameShaper::FlameShaper(const std::vector<FlameProfile>& profiles, const FlameShapeParams& params,
                         std::vector<ColorImage> images)
    : mParams(params), mImages(std::move(images)), mFlow(params.flowNoise, params.seed ^ 0xF10A5E11ull) {
  params.validate();
  if (profiles.empty()) throw std::invalid_argument("at least one flame profile is needed");
  if (mImages.size() > 1 && mImages.size() != profiles.size())
    throw std::invalid_argument("color images: give none, one, or one per profile (" +
                                std::to_string(profiles.size()) + ")");
  for (const ColorImage& image : mImages) image.validate();
  for (const FlameProfile& p : profiles) mDensities.push_back(std::make_unique<ProfileDensity>(p, params.density));
  mKolmogorov = std::make_unique<KolmogorovNoise>(params.kolmogorov, params.seed);
  mBlackbody = std::make_unique<BlackbodyRamp>(params.temperature);
}

int FlameShaper::profileIndex(const Flame& flame) const {
  return std::clamp(flame.source, 0, int(mDensities.size()) - 1);
}

const ProfileDensity& FlameShaper::density(int source) const {
  return *mDensities[std::size_t(std::clamp(source, 0, int(mDensities.size()) - 1))];
}

FlameShapeFrame FlameShaper::shape(const std::vector<Flame>& flames, double time, const FlameCamera& camera) const {
  FlameShapeFrame out;
  shape(flames, time, camera, out);
  return out;
}

void FlameShaper::shape(const std::vector<Flame>& flames, double time, const FlameCamera& camera,
                        FlameShapeFrame& out) const {
  camera.validate();
  if (!std::isfinite(time)) throw std::invalid_argument("time must be finite");
  for (std::size_t f = 0; f < flames.size(); ++f) checkFlame(flames[f], f);
  ThreadLimit limit(mParams.threads);
  const int count = int(flames.size());
  const std::size_t nf = flames.size();
  out.merged = out.obstructed = 0;
  out.sampled.assign(nf, 0);
  out.energy.assign(nf, 0.0);
  out.lights.assign(nf, FlameLight{});
  std::vector<std::unique_ptr<SpineFrame>> spines(nf);
  std::vector<double> factor(nf), mass(nf), power(nf);

  // Per flame: spine frame, sample count, eq. 5 and the eq. 6 factor, the mass per particle.
  parallelFor(0, count, [&](int f) {
    const Flame& flame = flames[std::size_t(f)];
    const ProfileDensity& density = *mDensities[std::size_t(profileIndex(flame))];
    auto spine = std::make_unique<SpineFrame>(flame);
    const double length = spine->length(), radius = shapeRadius(mParams, flame, length);
    const int n = particleCount(mParams.sampling, density, *spine, radius, camera);
    glm::dvec3 meanVelocity(0.0);
    double meanAge = 0.0;
    for (const SpinePoint& p : flame.points) meanVelocity += p.v, meanAge += p.age;
    meanVelocity /= double(flame.points.size());
    meanAge /= double(flame.points.size());
    // A separated piece's gas cools as it ages (FlameShapeParams::coolingTime): e^(−mean t_p / A).
    const double cooled =
        flame.separated && mParams.coolingTime > 0.0 ? std::exp(-meanAge / mParams.coolingTime) : 1.0;
    // Eq. 5 times the source's brightness (its Intensity in stops); a separated piece: its share
    // h / h_split of the flame it broke from (Flame::splitLength), fading with the life it has left
    // and as its gas cools.
    const bool piece = flame.separated && flame.splitLength > length;
    const double energy =
        flame.intensity * flame.brightness * lifeLeft(flame) * cooled *
        flameEnergy(mParams.incandescence, glm::length(meanVelocity), flame.radius, piece ? flame.splitLength : length) *
        pieceShare(flame, length);
    glm::dvec3 c, t, nn, b;
    spine->frameAt(0.5, &c, &t, &nn, &b);
    out.sampled[std::size_t(f)] = n;
    out.energy[std::size_t(f)] = energy;
    const double distance = glm::length(c - camera.position);
    factor[std::size_t(f)] = incandescenceFactor(energy, std::size_t(n), density.meanDensity(), length, distance);
    power[std::size_t(f)] = factor[std::size_t(f)] * 4.0 * kPi * (0.25 * length * length + distance * distance);
    // Canonical volume (widest radii³) to world: R² across, L / aspect along the spine.
    mass[std::size_t(f)] =
        flame.intensity * density.mass() * radius * radius * length / density.profile().aspect() / double(n);
    FlameLight& light = out.lights[std::size_t(f)];
    light.flameId = flame.id;
    light.centre = c;
    light.radius = length / 3.0;
    light.energy = energy;
    spines[std::size_t(f)] = std::move(spine);
  });

  std::vector<std::size_t> offset(nf + 1, 0);
  std::vector<Chunk> chunks;
  for (int f = 0; f < count; ++f) {
    const int n = out.sampled[std::size_t(f)];
    offset[std::size_t(f) + 1] = offset[std::size_t(f)] + std::size_t(n);
    for (int b = 0; b < n; b += kChunk) chunks.push_back({f, b, std::min(n, b + kChunk)});
  }
  FlameParticles& parts = out.particles;
  parts.resize(offset.back());
  std::vector<std::uint8_t> inside(offset.back());
  // Per chunk: Σ P_i c_i and Σ P_i lum(c_i) (the colour normalization and the light's colour).
  std::vector<glm::dvec3> chunkColor(chunks.size());
  std::vector<double> chunkLuminance(chunks.size()), chunkPower(chunks.size());
  const ObstacleSet* obstacles = mObstacles && !mObstacles->empty() ? mObstacles.get() : nullptr;

  // §4.5 merging: every flame's volume and neighbours, tested in the particle pass below (the
  // test reads only the spines, never the other flames' particles).
  const bool merging = mParams.merging && count > 1;
  std::vector<MergeVolume> volumes;
  std::vector<std::vector<int>> neighbours(nf);
  if (merging) {
    for (int f = 0; f < count; ++f) {
      const ProfileDensity& density = *mDensities[std::size_t(profileIndex(flames[std::size_t(f)]))];
      const double radius = shapeRadius(mParams, flames[std::size_t(f)], spines[std::size_t(f)]->length());
      MergeVolume v = mergeVolume(*spines[std::size_t(f)], density.profile(), radius);
      // Glow shell, the ends' extension along the tangents, and both noises.
      const double ends = (density.zMax() - density.profile().aspect()) / density.profile().aspect() *
                          spines[std::size_t(f)]->length();
      v.reach = std::max(radius * (density.rhoMax() - 1.0), ends) + radius * 2.0 * mParams.flowNoise.amplitude +
                3.0 * mParams.kolmogorov.amplitude;
      volumes.push_back(v);
    }
    neighbours = mergeNeighbours(volumes);
  }
  const KolmogorovFrame kolmogorov(*mKolmogorov, time);

  // Per particle: sample (eq. 4), colour (§5.1), flow noise, Figure 4, Kolmogorov noise, eq. 6,
  // obstacles and merging.
  parallelFor(0, int(chunks.size()), [&](int c) {
    const Chunk& chunk = chunks[std::size_t(c)];
    const Flame& flame = flames[std::size_t(chunk.flame)];
    const int pi = profileIndex(flame);
    const ProfileDensity& density = *mDensities[std::size_t(pi)];
    const ColorImage* image = mImages.empty() ? nullptr : &mImages[mImages.size() == 1 ? 0 : std::size_t(pi)];
    const SpineFrame& spine = *spines[std::size_t(chunk.flame)];
    const double aspect = density.profile().aspect(), radius = shapeRadius(mParams, flame, spine.length());
    // The colour image's v: a separated piece was the top h / h_split of its flame, so it takes
    // the top of the image (no blue base on a piece of flame with no fuel under it), and as its
    // life runs out and its gas ages it cools towards the tip's colour (v → 1): a breath of fire
    // reddens along its length, though its pieces split again and again.
    const double share = pieceShare(flame, spine.length()) * lifeLeft(flame);
    const double cooling = flame.separated && mParams.coolingTime > 0.0 ? 1.0 / mParams.coolingTime : 0.0;
    const int n = out.sampled[std::size_t(chunk.flame)];
    const std::vector<int>& near = neighbours[std::size_t(chunk.flame)];
    glm::dvec3 colorSum(0.0);
    double luminanceSum = 0.0, powerSum = 0.0;
    for (int i = chunk.begin; i < chunk.end; ++i) {
      const std::size_t m = offset[std::size_t(chunk.flame)] + std::size_t(i);
      const ProfileSample s = sampleFlame(density, mParams.seed, flame.id, i, n);
      glm::dvec3 p = s.position;
      glm::dvec3 velocity;
      double age;
      spine.motionAt(std::clamp(p.z / aspect, 0.0, 1.0), &velocity, &age);
      // §5.1: the image on the profile's side view (u across the widest diameter, v from base
      // to tip; the glow outside takes the nearest edge's colour), else a blackbody.
      const double cooled = cooling > 0.0 ? std::exp(-age * cooling) : 1.0;  // attached: no exp
      const double v = 1.0 - share * cooled * (1.0 - p.z / aspect);
      const glm::vec3 color = image && image->width > 0 ? image->sample(0.5 + 0.5 * p.x, v)
                                                        : (*mBlackbody)(s.density);
      p += mFlow.displacement(p, time - age, flame.radius);
      glm::dvec3 x = spine.map(p, aspect, radius);
      x += kolmogorov.displacement(x);
      parts.positions[m] = glm::vec3(x);
      parts.velocities[m] = glm::vec3(velocity);
      parts.colors[m] = color;
      parts.density[m] = float(flame.intensity * s.density);
      parts.incandescence[m] = float(factor[std::size_t(chunk.flame)] * s.density);
      const double particlePower = power[std::size_t(chunk.flame)] * s.density;
      parts.power[m] = float(particlePower);
      parts.mass[m] = float(mass[std::size_t(chunk.flame)]);
      parts.flame[m] = std::uint32_t(chunk.flame);
      // 2: dropped (its stored position inside an obstacle, §6.1).
      inside[m] = obstacles && obstacles->distance(glm::dvec3(parts.positions[m])) < 0.0 ? 2 : s.inside ? 1 : 0;
      if (inside[m] == 0 && !near.empty() && mergedAway(volumes, near, glm::dvec3(parts.positions[m]), false))
        inside[m] = 3;  // 3: merged (§4.5)
      colorSum += particlePower * glm::dvec3(color);
      luminanceSum += particlePower * double(luminance(color));
      powerSum += particlePower;
    }
    chunkPower[std::size_t(c)] = powerSum;
    chunkColor[std::size_t(c)] = colorSum;
    chunkLuminance[std::size_t(c)] = luminanceSum;
  });
  if (obstacles)
    for (std::size_t m = 0; m < parts.size(); ++m) out.obstructed += inside[m] == 2 ? 1 : 0;
  // Per flame, summed in chunk order (deterministic): its light's colour, the power-weighted
  // mean colour at luminance 1, and the scale s = Σ P_i / Σ P_i lum(c_i) giving its particles'
  // colours a power-weighted mean luminance of 1.
  std::vector<glm::dvec3> colorSum(nf, glm::dvec3(0.0));
  std::vector<double> luminanceSum(nf, 0.0), powerSum(nf, 0.0);
  for (std::size_t c = 0; c < chunks.size(); ++c) {
    const std::size_t f = std::size_t(chunks[c].flame);
    colorSum[f] += chunkColor[c];
    luminanceSum[f] += chunkLuminance[c];
    powerSum[f] += chunkPower[c];
  }
  std::vector<float> colorScale(nf, 1.f);
  for (std::size_t f = 0; f < nf; ++f)
    if (luminanceSum[f] > 0.0) {
      out.lights[f].color = glm::vec3(colorSum[f] / luminanceSum[f]);
      colorScale[f] = float(powerSum[f] / luminanceSum[f]);
    }
  parallelFor(0, int(chunks.size()), [&](int c) {
    const Chunk& chunk = chunks[std::size_t(c)];
    const float scale = colorScale[std::size_t(chunk.flame)];
    const std::size_t first = offset[std::size_t(chunk.flame)];
    for (int i = chunk.begin; i < chunk.end; ++i) parts.colors[first + std::size_t(i)] *= scale;
  });

  if (obstacles || merging) {
    std::size_t kept = 0;
    for (std::size_t m = 0; m < parts.size(); ++m) {
      if (inside[m] >= 2) continue;
      if (kept != m) {
        parts.positions[kept] = parts.positions[m];
        parts.velocities[kept] = parts.velocities[m];
        parts.colors[kept] = parts.colors[m];
        parts.density[kept] = parts.density[m];
        parts.incandescence[kept] = parts.incandescence[m];
        parts.power[kept] = parts.power[m];
        parts.mass[kept] = parts.mass[m];
        parts.flame[kept] = parts.flame[m];
      }
      ++kept;
    }
    out.merged = parts.size() - kept - out.obstructed;
    parts.resize(kept);
  }
}

}  // namespace plume
