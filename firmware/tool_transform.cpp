#include "firmware/tool_transform.hpp"

#include <cmath>

#include "firmware/fixed_point.hpp"

namespace ftstack::fw {

namespace {

using Mat = double[kAxes][kAxes];

[[nodiscard]] TransformStatus Validate(const ToolTransformParams& p) {
  for (std::size_t i = 0; i < 3; ++i) {
    if (!std::isfinite(p.d_m[i]) || !std::isfinite(p.r_deg[i])) return TransformStatus::kNotFinite;
    if (std::fabs(p.d_m[i]) > kMaxToolOffsetM || std::fabs(p.r_deg[i]) > kMaxToolAngleDeg) {
      return TransformStatus::kOutOfRange;
    }
  }
  return TransformStatus::kOk;
}

[[nodiscard]] bool IsZero(const ToolTransformParams& p) {
  for (std::size_t i = 0; i < 3; ++i) {
    if (p.d_m[i] != 0.0f || p.r_deg[i] != 0.0f) return false;
  }
  return true;
}

/// 6×6 matrix in output LSB (mN, 10 µN·m). mount = false: the tool transform
/// [Rᵀ 0; −Rᵀ[D]× Rᵀ]; mount = true: [R 0; [D]×R R].
void FloatMatrix(const ToolTransformParams& p, bool mount, Mat& m) {
  constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
  const double cx = std::cos(p.r_deg[0] * kDegToRad), sx = std::sin(p.r_deg[0] * kDegToRad);
  const double cy = std::cos(p.r_deg[1] * kDegToRad), sy = std::sin(p.r_deg[1] * kDegToRad);
  const double cz = std::cos(p.r_deg[2] * kDegToRad), sz = std::sin(p.r_deg[2] * kDegToRad);
  // R = Rz·Ry·Rx.
  const double r[3][3] = {{cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx},
                          {sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx},
                          {-sy, cy * sx, cy * cx}};
  const double d[3] = {p.d_m[0], p.d_m[1], p.d_m[2]};
  // Skew matrix of D: (D × F)_i = Σ_j dx[i][j] F_j.
  const double dx[3][3] = {{0, -d[2], d[1]}, {d[2], 0, -d[0]}, {-d[1], d[0], 0}};
  // Moments in 10 µN·m per (m · mN): 1 m · 1 mN = 1e-3 N·m = 100 LSB.
  const double lever_lsb = 1e-3 / kMomentLsbNm;
  for (std::size_t i = 0; i < kAxes; ++i) {
    for (std::size_t j = 0; j < kAxes; ++j) m[i][j] = 0.0;
  }
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      const double rot = mount ? r[i][j] : r[j][i];
      m[i][j] = rot;
      m[i + 3][j + 3] = rot;
      double lever = 0.0;
      for (std::size_t k = 0; k < 3; ++k) {
        lever += mount ? dx[i][k] * r[k][j] : r[k][i] * dx[k][j];  // [D]×R or Rᵀ[D]×
      }
      m[i + 3][j] = (mount ? 1.0 : -1.0) * lever_lsb * lever;
    }
  }
}

void Quantize(const Mat& m, FixedToolTransform* t) {
  for (std::size_t row = 0; row < kAxes; ++row) {
    double sum_abs = 0.0;
    for (std::size_t j = 0; j < kAxes; ++j) sum_abs += std::fabs(m[row][j]);
    // |w_j| ≤ 2^31: the worst partial sum is (sum_abs + 6 · ½) · 2^s · 2^31 (coefficients
    // rounded by at most half a unit each); keep it ≤ 2^62 so RoundShift cannot overflow.
    int s = 62 - 31 - static_cast<int>(std::ceil(std::log2(sum_abs + 6.0)));
    if (s > 62) s = 62;
    if (s < 0) s = 0;
    const double scale = std::ldexp(1.0, s);
    for (std::size_t j = 0; j < kAxes; ++j) t->coef[row][j] = std::llround(m[row][j] * scale);
    t->shift[row] = static_cast<std::uint8_t>(s);
  }
  t->identity = false;
}

}  // namespace

TransformStatus MakeToolTransform(const ToolTransformParams& params, FixedToolTransform* out) {
  return MakeMountedToolTransform(params, ToolTransformParams{}, out);
}

TransformStatus MakeMountedToolTransform(const ToolTransformParams& tool,
                                         const ToolTransformParams& mount,
                                         FixedToolTransform* out) {
  const TransformStatus st = Validate(tool);
  if (st != TransformStatus::kOk) return st;
  const TransformStatus sm = Validate(mount);
  if (sm != TransformStatus::kOk) return sm;
  FixedToolTransform t{};
  if (IsZero(tool) && IsZero(mount)) {
    *out = t;
    return TransformStatus::kOk;
  }
  Mat a{}, b{}, m{};
  FloatMatrix(tool, false, a);
  FloatMatrix(mount, true, b);
  for (std::size_t i = 0; i < kAxes; ++i) {
    for (std::size_t j = 0; j < kAxes; ++j) {
      double acc = 0.0;
      for (std::size_t k = 0; k < kAxes; ++k) acc += a[i][k] * b[k][j];
      m[i][j] = acc;
    }
  }
  Quantize(m, &t);
  *out = t;
  return TransformStatus::kOk;
}

std::uint8_t ToolFrameInvalidAxes(const FixedToolTransform& t, std::uint8_t sensor_invalid) {
  if (t.identity || sensor_invalid == 0) return sensor_invalid;
  std::uint8_t out = 0;
  for (std::size_t r = 0; r < kAxes; ++r) {
    for (std::size_t j = 0; j < kAxes; ++j) {
      if ((sensor_invalid & (1u << j)) != 0 && t.coef[r][j] != 0) out |= 1u << r;
    }
  }
  return out;
}

void ApplyToolTransform(const FixedToolTransform& t, const WrenchLsb& in, WrenchLsb* out,
                        bool* saturated) {
  if (t.identity) {
    *out = in;
    return;
  }
  WrenchLsb y{};
  for (std::size_t r = 0; r < kAxes; ++r) {
    std::int64_t acc = 0;
    for (std::size_t j = 0; j < kAxes; ++j) acc += t.coef[r][j] * in[j];
    y[r] = SatToI32(RoundShift(acc, t.shift[r]), saturated);
  }
  *out = y;
}

}  // namespace ftstack::fw
