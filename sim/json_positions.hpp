// Where each value of a JSON text starts (by JSON pointer), for file:line:column error messages.
#pragma once

#include <cstddef>
#include <map>
#include <string>

namespace ftstack::sim {

/// Byte offsets of every value in a syntactically valid JSON text, keyed by RFC 6901 pointer
/// ("" for the root, "/model/bridges/0/kind", …).
class JsonPositions {
 public:
  explicit JsonPositions(const std::string& text);
  /// "line:column" (1-based) of the value at `pointer`, or of its nearest listed ancestor.
  [[nodiscard]] std::string LineColumn(const std::string& pointer) const;

 private:
  void Scan(std::size_t& i, const std::string& pointer);
  void SkipSpace(std::size_t& i) const;
  std::string ReadString(std::size_t& i) const;

  const std::string& text_;
  std::map<std::string, std::size_t> offsets_;
};

/// "line:column" (1-based) of byte `offset` in `text`.
[[nodiscard]] std::string LineColumnAt(const std::string& text, std::size_t offset);

}  // namespace ftstack::sim
