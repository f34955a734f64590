/// \file fuzz_tracer_state.cpp
/// Fuzz target of the tracer checkpoint reader (tracers/tracer_state_file.h): readTracerState
/// on any bytes returns or throws std::runtime_error naming the file; a tracer that read a file
/// then takes one step through uniform fields.

#include "fuzz_common.h"
#include "fuzz_fixtures.h"
#include "tracers/tracer_state_file.h"

using namespace plume;

PLUME_FUZZ_RESIGNING_MUTATOR(fuzz::resignTrailer)

namespace {

struct Fields {
  MacGrid3 before, after;
  ScalarGrid density;
  Fields() {
    const glm::ivec3 n = fuzz::tracerGrid().resolution;
    for (MacGrid3* m : {&before, &after}) {
      m->resize(n);
      m->u().fill(0.1f);
      m->v().fill(-0.05f);
      m->w().fill(0.9f);
    }
    density.resize(n);
    density.fill(0.5f);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::TempInput input("tracer_state");
  static const Fields fields;
  const std::string& path = input.write(data, size);
  StreakTracer tracer = fuzz::makeTracer();
  if (fuzz::expectClean(path, [&] { readTracerState(path, tracer); }))
    tracer.step(fields.before, fields.after, fields.density, 0.05f);
  return 0;
}
