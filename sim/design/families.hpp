// Structural families of sensor bodies: each a generator of a linear DesignModel from parameters.
#pragma once

#include <string>

#include "sim/adc_models.hpp"
#include "sim/design/design.hpp"
#include "sim/design/frame.hpp"
#include "sim/physical_sensor.hpp"

namespace ftstack::sim::design {

/// The read-out every generated family uses unless told otherwise: ADS131M06 at gain 128,
/// 1000 SPS, 3.3 V excitation (noise from sim/adc_models); gauges GF 2.0, full bridges.
struct Readout {
  AdcSpec adc;
  double gauge_factor = 2.0;
};
/// Per-bridge noise in mV/V RMS of the read-out, and its bandwidth (data rate / 2, assumed).
[[nodiscard]] double ReadoutNoiseMvv(const Readout& r);

/// Hub-and-spoke bodies from an existing physical sensor model (a sensor description).
[[nodiscard]] DesignModel FromPhysicalSensor(const PhysicalSensorModel& s, const Material& mat,
                                             double bridge_noise_mvv, double rate_hz);

/// Family "hub-spoke": 3 or 4 radial beams, classic bending bridges at gauge_frac of the length.
struct HubSpokeParams {
  int beams = 4;
  double hub_radius_m = 0.015, rim_radius_m = 0.05;
  double beam_width_m = 0.008, beam_height_m = 0.01;
  double gauge_frac = 0.15;
  Material material = Steel174Ph();
  /// Beam roots compliant in an elastic hub and rim (FlexureGeometry::elastic_roots).
  bool elastic_roots = false;
};
[[nodiscard]] DesignModel HubSpoke(const HubSpokeParams& p, const Readout& r);

/// Family "guided": three nested parallelogram stages in series (platform → z stage → x stage →
/// y stage → ground). Each stage is two mirrored parallelograms of two leaves (length L, width b,
/// thickness t, leaves `separation` apart along the compliant axis): it yields only to a force
/// along its compliant axis (leaf S-bending, force bridge at the leaf roots) while moments load
/// the leaves axially or about their strong axis (moment bridge at mid-leaf, where the guided
/// bending vanishes). Intermediate stages are rigid bodies; joints are ideal clamps.
struct GuidedParams {
  double leaf_length_m = 0.03;
  double leaf_width_m = 0.03;
  double leaf_thickness_m = 0.0015;  ///< x and y stages
  double leaf_thickness_z_m = 0.0015;
  double separation_m = 0.04;    ///< between the two leaves of a parallelogram
  double inner_radius_m = 0.02;  ///< innermost leaf roots from the axis
  double gap_m = 0.01;           ///< radial gap between nested stages
  double gauge_frac = 0.1;       ///< force gauges this fraction of L from the outer root
  int elements_per_leaf = 1;     ///< mesh (exact beam elements: refinement changes nothing)
  Material material = Steel174Ph();
};
[[nodiscard]] FrameModel GuidedFrame(const GuidedParams& p);
[[nodiscard]] DesignModel Guided(const GuidedParams& p, const Readout& r);

}  // namespace ftstack::sim::design
