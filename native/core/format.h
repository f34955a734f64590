#pragma once
/// \file format.h
/// Numbers in error messages: the short form a user reads back ("0.25", "1e+06", "nan").

#include <sstream>
#include <string>

namespace plume {

/// v as an ostream prints it (6 significant digits).
inline std::string formatNumber(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace plume
