#include "tracers/tracer_driver.h"

#include "core/parallel.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace plume {
namespace {

/// Connects a StreakTracer to the solver's steps: the velocity before each step is kept so the
/// particles can use the midpoint of the step in time.
class TracerObserver final : public StepObserver {
 public:
  explicit TracerObserver(StreakTracer& tracer) : mTracer(tracer) {}
  void beforeStep(const SmokeSolver& solver) override {
    mTracer.previousVelocity() = solver.velocity();  // reuses the buffers after the first step
  }
  void afterStep(const SmokeSolver& solver, float dt) override {
    mTracer.observeStep(solver, mTracer.previousVelocity(), dt);
  }
  bool cancelRequested() override { return mTracer.consumeCancel(); }

 private:
  StreakTracer& mTracer;
};

}  // namespace

bool advanceFrameWithTracers(SmokeSolver& solver, StreakTracer& tracer) {
  TracerObserver observer(tracer);
  return solver.advanceFrame(&observer);
}

}  // namespace plume
