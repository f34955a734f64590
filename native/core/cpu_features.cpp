#include "core/cpu_features.h"

namespace plume {

bool hasAvx2() {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(PLUME_NO_AVX2)
  static const bool has = [] {
    __builtin_cpu_init();  // may run before libgcc's own constructor
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return has;
#else
  return false;
#endif
}

}  // namespace plume
