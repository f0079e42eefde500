// errno as text for error messages, thread-safe (strerror_r, whichever variant the C library has).
#pragma once

#include <cstring>

#include <cstddef>

namespace ftstack::hal {

namespace detail {
/// GNU strerror_r returns the text (maybe not in buf).
inline const char* StrerrorResult(const char* text, const char* /*buf*/) { return text; }
/// XSI strerror_r returns 0 on success and writes buf.
inline const char* StrerrorResult(int rc, const char* buf) {
  return rc == 0 ? buf : "unknown error";
}
}  // namespace detail

/// A fixed-size buffer holding the text of one errno value (no heap, safe from any thread).
class ErrnoText {
 public:
  explicit ErrnoText(int err)
      : text_(detail::StrerrorResult(::strerror_r(err, buf_, sizeof buf_), buf_)) {}
  [[nodiscard]] const char* c_str() const { return text_; }

 private:
  char buf_[96] = {};
  const char* text_;
};

}  // namespace ftstack::hal
