/// \file toon_coherence_test.cpp
/// Temporal coherence of the toon outlines (issue 5; cartoon_smoke.txt §2.3: "choosing [the
/// in-plane rotation] randomly per frame produces temporal incoherence. Instead, we orient the
/// stencil in the velocity direction"). A steady plume is advanced frame by frame, its particles
/// are drawn into a depth buffer as stretched, rotated stencils seen from the side, and the
/// outlines of §2.2 (depthDifferences) are compared between consecutive frames, once with the
/// orientation of billboard.h and once with the same particles at random angles.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "tests/toon_plume.h"
#include "toon/billboard.h"
#include "toon/depth_differences.h"
#include "toon/toon_particles.h"

namespace plume {
namespace {

using testing::plumeFields;
using testing::plumeGrid;
using testing::plumeSources;

/// An orthographic side view: the image plane spans world x (right) and z (up), the camera
/// looks along +y from y = -10 m; image `width` x `height` pixels of `pixel` metres, centred
/// on world (centreX, centreZ).
struct SideView {
  int width = 240, height = 320;
  float pixel = 0.0105f, centreX = 0.8f, centreZ = 1.6f;

  ToonCamera camera() const {
    glm::dmat4 m(1.0);
    m[0] = glm::dvec4(1, 0, 0, 0);                    // right: +x
    m[1] = glm::dvec4(0, 0, 1, 0);                    // up: +z
    m[2] = glm::dvec4(0, -1, 0, 0);                   // backward: -y (looks along +y)
    m[3] = glm::dvec4(centreX, -10.0, centreZ, 1.0);  // location
    return ToonCamera{m, /*perspective=*/false};
  }
};

/// Test-only splatter: the depth pass of §2.2 with the circle stencil of Figure 3 stretched
/// along its in-plane axis (Figure 4). Particle n is a camera-facing ellipse centred on its
/// projection, semi-axes size·stretch/2 along angle[n] (from the image's +x toward +y, as
/// billboard.h measures it) and size/2 across, at the particle's depth (a camera-facing flat
/// stencil has one depth under an orthographic camera). A pixel whose centre lies inside keeps
/// the smallest depth over the particles covering it; the background is +inf. Row 0 is the top.
std::vector<float> splat(const SideView& view, const ToonParticleState& s,
                         const std::vector<float>& angle, const std::vector<float>& stretch) {
  const int w = view.width, h = view.height;
  std::vector<float> depth(std::size_t(w) * std::size_t(h), std::numeric_limits<float>::infinity());
  for (std::size_t n = 0; n < s.count(); ++n) {
    if (!(s.size[n] > 0.f)) continue;
    const glm::vec3 p = s.positions[n];
    // Image coordinates in pixels (x right, y up) of the centre; depth along the view (+y).
    const float cx = (p.x - view.centreX) / view.pixel + 0.5f * float(w);
    const float cy = (p.z - view.centreZ) / view.pixel + 0.5f * float(h);
    const float z = p.y + 10.f;
    const float a = 0.5f * s.size[n] * stretch[n] / view.pixel, b = 0.5f * s.size[n] / view.pixel;
    const float ca = std::cos(angle[n]), sa = std::sin(angle[n]);
    const int i0 = std::max(0, int(std::floor(cx - a))),
              i1 = std::min(w - 1, int(std::ceil(cx + a)));
    const int j0 = std::max(0, int(std::floor(cy - a))),
              j1 = std::min(h - 1, int(std::ceil(cy + a)));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const float dx = float(i) + 0.5f - cx, dy = float(j) + 0.5f - cy;
        const float along = (dx * ca + dy * sa) / a, across = (-dx * sa + dy * ca) / b;
        if (along * along + across * across > 1.f) continue;
        float& d = depth[std::size_t(h - 1 - j) * std::size_t(w) + std::size_t(i)];
        d = std::min(d, z);
      }
  }
  return depth;
}

/// Outline pixels changed between consecutive frames, over the frames of a sequence.
struct Flicker {
  std::size_t changed = 0;  ///< sum over frame pairs of |O_f xor O_f+1|
  std::size_t outline = 0;  ///< sum over frame pairs of |O_f or O_f+1|
  /// The fraction of outline pixels that change: pixels in the outline of one frame of a pair
  /// but not of the other, over the pixels in the outline of either (0: identical outlines,
  /// 1: disjoint ones), pooled over every consecutive pair.
  double fraction() const { return outline ? double(changed) / double(outline) : 0.0; }
  void add(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    for (std::size_t m = 0; m < a.size(); ++m) {
      changed += std::size_t(a[m] != b[m]);
      outline += std::size_t(a[m] | b[m]);
    }
  }
};

TEST(ToonCoherence, VelocityOrientedOutlinesFlickerAtMostHalfAsMuchAsRandomOnes) {
  // The plume fixture (16 x 16 x 32 cells of 10 cm, rising at 1 m/s and turning about its axis)
  // with the same fields every frame: a steady plume.
  const GridFrame g = plumeGrid(16, 0.1f);
  const ToonFields f = plumeFields(g);
  ToonParams p = testing::plumeParams();
  p.sizeLow = 0.04f;  // stencils of 4 to 12 cm (4 to 11 pixels) in 10 cm cells
  p.sizeHigh = 0.12f;
  p.seed = 3;
  ToonParticles t(p, g);
  // Stretch 1 + k |v_screen| ≈ 2 at the plume's 1 m/s: the stencils are visibly stretched.
  const float stretchFactor = 1.f;
  // The frame time: 1/240 s, so that the smoke moves 4 mm (0.4 pixel) per frame and what changes
  // between two frames is the stencils' flicker, not the smoke's own motion. At 1/24 s it moves
  // 4 pixels per frame and a 2-pixel-wide outline changes almost everywhere whatever the
  // orientation (measured: 0.69 oriented, 0.77 random); at 1/120 s, 0.30 against 0.71.
  const float dt = 1.f / 240.f;
  for (int frame = 0; frame < 40; ++frame) t.advanceFrame(f, f, dt, plumeSources(g));

  const SideView view;
  DepthDifferenceParams dd;
  dd.gamma = 0.1f;  // the add-on's default γ, depth in metres per pixel (Δx = Δy = 1 pixel)
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> turn(-3.14159265f, 3.14159265f);
  auto outline = [&](const std::vector<float>& depth) {
    std::vector<std::uint8_t> o(depth.size());
    depthDifferences(depth.data(), view.width, view.height, dd, o.data());
    return o;
  };
  Flicker oriented, random;
  std::vector<std::uint8_t> lastOriented, lastRandom;
  std::size_t outlinePixels = 0;
  for (int frame = 0; frame <= 10; ++frame) {
    if (frame > 0) t.advanceFrame(f, f, dt, plumeSources(g));
    const ToonParticleState& s = t.state();
    const Billboards b = computeBillboards(view.camera(), s.positions, s.velocities, stretchFactor);
    std::vector<float> randomAngle(s.count());
    for (float& a : randomAngle) a = turn(rng);
    const std::vector<std::uint8_t> o = outline(splat(view, s, b.angle, b.stretch));
    const std::vector<std::uint8_t> r = outline(splat(view, s, randomAngle, b.stretch));
    if (frame > 0) {
      oriented.add(lastOriented, o);
      random.add(lastRandom, r);
    }
    lastOriented = o;
    lastRandom = r;
    for (std::uint8_t v : o) outlinePixels += v;
    if (frame == 0) {
      // The setting is what the test claims: a plume of stretched stencils with outlines.
      ASSERT_GT(s.count(), 1000u);  // measured 1554
      float most = 1.f;
      for (float x : b.stretch) most = std::max(most, x);
      EXPECT_GT(most, 1.5f);
      EXPECT_LT(most, 2.5f);
    }
  }
  ASSERT_GT(outlinePixels, 11u * 2000u);  // measured ~3200 outline pixels per frame
  std::printf("outline pixels changing per frame: velocity-oriented %.4f, random %.4f\n",
              oriented.fraction(), random.fraction());
  // Issue 5: at most half of the random orientation's flicker. Both sequences share particles,
  // sizes and stretch, so only the in-plane angle differs. Random angles redraw every stencil
  // every frame (measured 0.72 of the outline pixels change); along the velocity of a steady
  // flow a stencil turns little (measured 0.19: the motion, births and growth), a ratio of 0.26
  // against the 0.5. Drawing the oriented sequence at random angles too gives 0.72
  // against 0.72 and fails, as it must.
  EXPECT_LE(oriented.fraction(), 0.5 * random.fraction());
}

}  // namespace
}  // namespace plume
