#pragma once
/// \file utf8_text.h
/// Error messages hold names read from files: bytes that are not UTF-8 are escaped, so Python
/// receives the message (pybind11 turns an invalid message into an empty exception).

#include <string>

namespace plume {

/// `text` with every byte that is not part of a valid UTF-8 sequence (and every control byte
/// but tab and newline) written as \xNN.
std::string cleanUtf8(const std::string& text);

}  // namespace plume
