#include "sim/json_positions.hpp"

namespace ftstack::sim {

std::string LineColumnAt(const std::string& text, std::size_t offset) {
  std::size_t line = 1;
  std::size_t col = 1;
  for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return std::to_string(line) + ":" + std::to_string(col);
}

JsonPositions::JsonPositions(const std::string& text) : text_(text) {
  std::size_t i = 0;
  Scan(i, "");
}

void JsonPositions::SkipSpace(std::size_t& i) const {
  while (i < text_.size() &&
         (text_[i] == ' ' || text_[i] == '\t' || text_[i] == '\n' || text_[i] == '\r')) {
    ++i;
  }
}

std::string JsonPositions::ReadString(std::size_t& i) const {
  std::string out;
  ++i;  // opening quote
  while (i < text_.size() && text_[i] != '"') {
    if (text_[i] == '\\' && i + 1 < text_.size()) ++i;  // escapes: keep the escaped character
    out += text_[i++];
  }
  ++i;  // closing quote
  return out;
}

void JsonPositions::Scan(std::size_t& i, const std::string& pointer) {
  SkipSpace(i);
  if (i >= text_.size()) return;
  offsets_[pointer] = i;
  const char c = text_[i];
  if (c == '{' || c == '[') {
    const char close = c == '{' ? '}' : ']';
    ++i;
    for (int index = 0;; ++index) {
      SkipSpace(i);
      if (i >= text_.size()) return;
      if (text_[i] == close) {
        ++i;
        return;
      }
      std::string key = std::to_string(index);
      if (c == '{') {
        key.clear();
        for (char k : ReadString(i)) {  // RFC 6901 escaping
          if (k == '~') {
            key += "~0";
          } else if (k == '/') {
            key += "~1";
          } else {
            key += k;
          }
        }
        SkipSpace(i);
        ++i;  // ':'
      }
      Scan(i, pointer + "/" + key);
      SkipSpace(i);
      if (i < text_.size() && text_[i] == ',') ++i;
    }
  }
  if (c == '"') {
    (void)ReadString(i);
    return;
  }
  while (i < text_.size() && text_[i] != ',' && text_[i] != ']' && text_[i] != '}' &&
         text_[i] != ' ' && text_[i] != '\n' && text_[i] != '\r' && text_[i] != '\t') {
    ++i;
  }
}

std::string JsonPositions::LineColumn(const std::string& pointer) const {
  std::string p = pointer;
  for (;;) {
    const auto it = offsets_.find(p);
    if (it != offsets_.end()) return LineColumnAt(text_, it->second);
    if (p.empty()) return "1:1";
    p.erase(p.rfind('/'));
  }
}

}  // namespace ftstack::sim
