// Text placed into the project's HTML reports (diagnosis, calibration, design): escaping.
#pragma once

#include <string>

namespace ftstack {

/// `s` with the characters HTML gives a meaning to in text and in quoted attribute values
/// (& < > ") replaced by their entities; every other byte unchanged (UTF-8 passes through).
[[nodiscard]] std::string HtmlEscape(const std::string& s);

}  // namespace ftstack
