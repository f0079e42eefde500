// Robot and machine work cycles as load profiles: the days a sensor's health watch must hold on.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim/load_profile.hpp"

namespace ftstack::sim {

/// The work cycles, by name:
///   machine-tending  a tool on the wrist (tared); a part of 1–2 % of rated Fz × 10 (4–8 kg on
///                    the built-in sensor) picked with a 10 ms edge, re-oriented 20–60° 2.5–5 s
///                    after the pick, a press-fit, released, idle 3–12 s; 19 → 27 °C and back
///   palletising      cases of 25–60 % of rated Fz lifted over 0.3 s, carried 10–30 s (slow
///                    swing moments), placed, 5–10 s back empty; a hall at 15 → 22 °C and back
///   assembly         a light part; contact with a 5 ms edge and a decaying bounce, an insertion
///                    ramp with lateral jitter, release; 6–10 s per part; 21–23 °C
///   polishing        continuous contact force with slow variation and friction turning with the
///                    path, 20–60 s passes, 2–5 s lift-offs; a spindle's vibration all day
///                    (larger in contact); the body warms by ≈ 6 K with the spindle
///   hand-guiding     an operator steers the arm: every axis moving slowly and smoothly, no holds,
///                    10–30 min sessions between 1–5 min parked; 21–23 °C
///   screwdriving     4–8 screws per part: push, Mz built up over 0.3–0.8 s to 25–75 % of rated,
///                    dropped in 5 ms at the clutch; 21–24 °C
///   night-idle       no load at all; the hall's night set-back: 18 ↔ 26 °C in 2–4 h cycles with a
///                    0.5 K 20-min ripple
/// Loads are shares of `rated`, so a cycle fits any sensor. Deterministic per seed; `duration_s`
/// 0 gives 24 h. Default rate 1 kHz. Throws ProfileError for an unknown name.
[[nodiscard]] LoadProfile MakeWorkCycle(const std::string& name, const Wrench& rated,
                                        std::uint64_t seed, double duration_s);

/// The names MakeWorkCycle knows.
[[nodiscard]] const std::vector<std::string>& WorkCycleNames();

}  // namespace ftstack::sim
