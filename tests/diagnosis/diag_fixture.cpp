// The diagnosis tests' closed-form sim/real generator (see diag_fixture.hpp).
#include "tests/diagnosis/diag_fixture.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace ftstack::diag::testing {

Eigen::Matrix<double, 6, 1> RigProfile::At(double tq) const {
  if (tq <= t.front()) return w.front();
  if (tq >= t.back()) return w.back();
  const auto it = std::upper_bound(t.begin(), t.end(), tq);
  const std::size_t i = static_cast<std::size_t>(it - t.begin()) - 1;
  const double u = (tq - t[i]) / (t[i + 1] - t[i]);
  return w[i] + u * (w[i + 1] - w[i]);
}

RigProfile MakeRig(unsigned seed, double hold_s) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> amp(0.5, 0.9);
  const Eigen::Matrix<double, 6, 1> rated = sim::DefaultRated();
  RigProfile p;
  Eigen::Matrix<double, 6, 1> cur = Eigen::Matrix<double, 6, 1>::Zero();
  double t = 0.0;
  auto key = [&](double dt, const Eigen::Matrix<double, 6, 1>& w) {
    t += dt;
    p.t.push_back(t);
    p.w.push_back(w);
    cur = w;
  };
  key(0.0, cur);
  key(3.0, cur);
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 6, 1> w = Eigen::Matrix<double, 6, 1>::Zero();
    const double a = amp(rng) * rated(k);
    w(k) = a;
    key(2.0, w);
    key(hold_s, w);
    w(k) = a / 2;  // down-sweep stage: reached from above
    key(1.0, w);
    key(hold_s / 2, w);
    w(k) = -a;
    key(3.0, w);
    key(hold_s, w);
    w(k) = -a / 2;
    key(1.0, w);
    key(hold_s / 2, w);
    w(k) = a / 2;  // reached from below
    key(2.0, w);
    key(hold_s / 2, w);
    w(k) = 0;
    key(1.5, w);
    key(hold_s / 2, w);
  }
  // Combined loads: axial with bending/shear.
  const int combos[4][2] = {{2, 3}, {2, 0}, {2, 4}, {2, 1}};
  for (const auto& cb : combos) {
    Eigen::Matrix<double, 6, 1> w = Eigen::Matrix<double, 6, 1>::Zero();
    w(cb[0]) = (rng() % 2 ? 1 : -1) * amp(rng) * rated(cb[0]);
    w(cb[1]) = (rng() % 2 ? 1 : -1) * amp(rng) * rated(cb[1]);
    key(2.0, w);
    key(hold_s, w);
    key(2.0, Eigen::Matrix<double, 6, 1>::Zero());
    key(2.0, Eigen::Matrix<double, 6, 1>::Zero());
  }
  // Fast taps (20 ms edges).
  for (int j = 0; j < 8; ++j) {
    Eigen::Matrix<double, 6, 1> w = Eigen::Matrix<double, 6, 1>::Zero();
    const int k = j % 2 == 0 ? 2 : 0;
    w(k) = 0.6 * rated(k);
    key(0.02, w);
    key(1.5, w);
    key(0.02, Eigen::Matrix<double, 6, 1>::Zero());
    key(1.5, Eigen::Matrix<double, 6, 1>::Zero());
  }
  return p;
}

double Temperature(double t) {
  return 20.0 + 6.0 * (1.0 - std::exp(-t / 90.0)) + 0.6 * std::sin(2 * M_PI * t / 70.0);
}

Fixture MakeFixture(const std::vector<FixtureEffect>& effects, unsigned seed, double rate_hz,
                    double noise, double hold_s) {
  const RigProfile rig = MakeRig(seed, hold_s);
  const auto sensor = sim::MakeDefaultSensor();
  const Eigen::MatrixXd s = sensor->Sensitivity();
  const Eigen::Matrix<double, 6, 1> rated = sim::DefaultRated();
  const int nc = 6;
  const auto n = static_cast<int>(rig.duration() * rate_hz);
  Fixture fx;
  DiagData& d = fx.data;
  d.sim_name = "fixture-sim";
  d.real_name = "fixture-real";
  d.t_s.resize(static_cast<std::size_t>(n));
  d.wrench.resize(n, 6);
  d.sim_mvv.resize(n, nc);
  d.temp_c.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double t = i / rate_hz;
    d.t_s[static_cast<std::size_t>(i)] = t;
    d.wrench.row(i) = rig.At(t).transpose().cast<float>();
    d.sim_mvv.row(i) = (s * rig.At(t)).transpose();
    d.temp_c[static_cast<std::size_t>(i)] = Temperature(t);
  }
  const double lmax = d.sim_mvv.cwiseAbs().maxCoeff();
  Eigen::MatrixXd real = d.sim_mvv;
  std::mt19937 rng(seed * 7919u + 17u);
  std::normal_distribution<double> g(0.0, 1.0);
  for (const auto& e : effects) {
    const double a = e.size_sigma * noise;
    const std::string& nm = e.name;
    if (nm == "zero_offset") {
      for (int c = 0; c < nc; ++c) real.col(c).array() += (c == 2 ? a : 0.3 * a * g(rng));
      fx.truth = a;
      fx.truth_channel = 2;
    } else if (nm == "zero_drift") {
      for (int i = 0; i < n; ++i) {
        const double t = d.t_s[static_cast<std::size_t>(i)];
        const double v =
            std::sin(2 * M_PI * t / 130.0 + 0.3) + 0.5 * std::sin(2 * M_PI * t / 47.0 + 1.1);
        for (int c = 0; c < nc; ++c) real(i, c) += a / 1.5 * v * (c == 1 ? 1.0 : 0.3);
      }
    } else if (nm == "thermal_zero_drift") {
      const double coef = a / 6.5;
      fx.truth = coef;
      fx.truth_channel = 4;
      for (int i = 0; i < n; ++i) {
        for (int c = 0; c < nc; ++c)
          real(i, c) +=
              coef * (c == 4 ? 1.0 : 0.2) * (d.temp_c[static_cast<std::size_t>(i)] - 20.0);
      }
    } else if (nm == "thermal_span_drift") {
      const double coef = a / (lmax * 6.5);
      fx.truth = coef;
      for (int i = 0; i < n; ++i)
        real.row(i) += coef * (d.temp_c[static_cast<std::size_t>(i)] - 20.0) * d.sim_mvv.row(i);
    } else if (nm == "excitation_drift") {
      for (int i = 0; i < n; ++i) {
        const double t = d.t_s[static_cast<std::size_t>(i)];
        const double f =
            a / lmax * (0.7 * std::sin(2 * M_PI * t / 110.0) + 0.3 * std::cos(2 * M_PI * t / 37.0));
        real.row(i) += f * d.sim_mvv.row(i);
      }
    } else if (nm == "creep") {
      const double tau = 12.0;
      const double beta = a / lmax;
      fx.truth = tau;
      // dy/dt = (L(t) − y)/τ by RK4 on 10 sub-steps of the continuous profile.
      Eigen::VectorXd y = s * rig.At(0.0);
      for (int i = 0; i < n; ++i) {
        if (i > 0) {
          const double h = 1.0 / rate_hz / 10.0;
          double t = d.t_s[static_cast<std::size_t>(i - 1)];
          for (int k = 0; k < 10; ++k) {
            auto f = [&](double tt, const Eigen::VectorXd& yy) {
              return Eigen::VectorXd((s * rig.At(tt) - yy) / tau);
            };
            const Eigen::VectorXd k1 = f(t, y);
            const Eigen::VectorXd k2 = f(t + h / 2, y + h / 2 * k1);
            const Eigen::VectorXd k3 = f(t + h / 2, y + h / 2 * k2);
            const Eigen::VectorXd k4 = f(t + h, y + h * k3);
            y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
            t += h;
          }
        }
        real.row(i) += beta * y.transpose();
      }
    } else if (nm == "hysteresis") {
      // Play operator of width 20 % of each channel's range: output lags the input by ±w/2.
      for (int c = 0; c < nc; ++c) {
        const double range = d.sim_mvv.col(c).maxCoeff() - d.sim_mvv.col(c).minCoeff();
        const double w = 0.2 * range;
        double play = d.sim_mvv(0, c);
        for (int i = 0; i < n; ++i) {
          const double x = d.sim_mvv(i, c);
          play = std::clamp(play, x - w / 2, x + w / 2);
          real(i, c) += a * (play - x) / (w / 2);
        }
      }
    } else if (nm == "bridge_nonlinearity") {
      for (int c : {1, 4}) {
        const double m = d.sim_mvv.col(c).cwiseAbs().maxCoeff();
        real.col(c).array() += a / (m * m) * d.sim_mvv.col(c).array().square();
      }
      fx.truth_channel = 1;
    } else if (nm == "geometric_nonlinearity") {
      for (int i = 0; i < n; ++i) {
        Eigen::Matrix<double, 6, 1> w = d.wrench.row(i).transpose().cast<double>();
        Eigen::Matrix<double, 6, 1> dw;
        for (int k = 0; k < 6; ++k) dw(k) = -w(k) * std::pow(w(k) / rated(k), 2);
        real.row(i) += (a / 0.6 / 0.73 * s * dw).transpose();
      }
    } else if (nm == "load_stiffening") {
      const double kap = a / 0.6 / 0.6;
      for (int i = 0; i < n; ++i) {
        Eigen::Matrix<double, 6, 1> w = d.wrench.row(i).transpose().cast<double>();
        Eigen::Matrix<double, 6, 1> dw = Eigen::Matrix<double, 6, 1>::Zero();
        for (int k : {0, 1, 3, 4}) dw(k) = kap * w(2) / rated(2) * w(k);
        real.row(i) += (s * dw).transpose();
      }
    } else if (nm == "misalignment") {
      // Sensor frame rotated by +θ about z: it reads Rᵀ·F, Rᵀ·M.
      const double th = a / 0.6;  // small-angle: cross-talk ≈ θ × rated output
      fx.truth = th * 180.0 / M_PI;
      const double c0 = std::cos(th);
      const double s0 = std::sin(th);
      for (int i = 0; i < n; ++i) {
        Eigen::Matrix<double, 6, 1> w = d.wrench.row(i).transpose().cast<double>();
        Eigen::Matrix<double, 6, 1> ws = w;
        ws(0) = c0 * w(0) + s0 * w(1);
        ws(1) = -s0 * w(0) + c0 * w(1);
        ws(3) = c0 * w(3) + s0 * w(4);
        ws(4) = -s0 * w(3) + c0 * w(4);
        real.row(i) += (s * (ws - w)).transpose();
      }
    } else if (nm == "gain_error") {
      const double m = d.sim_mvv.col(3).cwiseAbs().maxCoeff();
      fx.truth = 1.0 + a / m;
      fx.truth_channel = 3;
      real.col(3) *= 1.0 + a / m;
    } else if (nm == "time_skew") {
      const double delay = 1.0 / rate_hz;
      fx.truth = delay;
      for (int i = 0; i < n; ++i) {
        real.row(i) += (s * (rig.At(d.t_s[static_cast<std::size_t>(i)] - delay) -
                             rig.At(d.t_s[static_cast<std::size_t>(i)])))
                           .transpose();
      }
    } else if (nm == "saturation") {
      const double lim = 0.8 * lmax;
      fx.truth = lim;
      real = real.cwiseMax(-lim).cwiseMin(lim);
    } else if (nm == "overload_shift") {
      const double onset = 0.55 * rig.duration();
      fx.truth = onset;
      for (int i = 0; i < n; ++i) {
        if (d.t_s[static_cast<std::size_t>(i)] >= onset) {
          real(i, 0) += a;
          real(i, 5) -= 0.5 * a;
        }
      }
    } else if (nm == "mains_interference") {
      fx.truth = 50.0;
      for (int c = 0; c < nc; ++c) {
        const double amp_c = a * (c == 0 ? 1.0 : 0.4);
        const double ph = 0.7 * c;
        for (int i = 0; i < n; ++i)
          real(i, c) += amp_c * std::sin(2 * M_PI * 50.0 * d.t_s[static_cast<std::size_t>(i)] + ph);
      }
    } else if (nm == "resonance") {
      const double f0 = 23.0;
      const double z = 0.04;
      fx.truth = f0;
      const double w0 = 2 * M_PI * f0;
      for (int c = 0; c < nc; ++c) {
        double y = d.sim_mvv(0, c);
        double v = 0.0;
        const int sub = 20;
        const double h = 1.0 / rate_hz / sub;
        for (int i = 1; i < n; ++i) {
          double t = d.t_s[static_cast<std::size_t>(i - 1)];
          for (int k = 0; k < sub; ++k) {
            auto acc = [&](double tt, double yy, double vv) {
              return w0 * w0 * ((s.row(c) * rig.At(tt))(0) - yy) - 2 * z * w0 * vv;
            };
            const double a1 = acc(t, y, v);
            const double a2 = acc(t + h / 2, y + h / 2 * v, v + h / 2 * a1);
            const double a3 = acc(t + h / 2, y + h / 2 * (v + h / 2 * a1), v + h / 2 * a2);
            const double a4 = acc(t + h, y + h * (v + h / 2 * a2), v + h * a3);
            y += h * (v + h / 6 * (a1 + a2 + a3));
            v += h / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
            t += h;
          }
          real(i, c) += y - d.sim_mvv(i, c);
        }
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int c = 0; c < nc; ++c) real(i, c) += noise * g(rng);
  }
  d.real_mvv = real;
  return fx;
}

}  // namespace ftstack::diag::testing
