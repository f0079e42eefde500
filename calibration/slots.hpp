// Two calibration slots (A/B) on the device with atomic replacement and fallback to the previous
// one.
#pragma once

#include <string>

#include "calibration/cal_file.hpp"

namespace ftstack::cal {

/// A directory holding cal_A.json, cal_B.json and `active` (one line: "A" or "B"). A new
/// calibration is verified, written into the inactive slot (temporary file, fsync, rename),
/// read back and verified again, and only then made active by replacing `active` atomically.
/// A refused file never touches the active slot. If the active slot is found corrupt when
/// loading, the other slot (the previous calibration) is used and the reason reported.
class CalSlots {
 public:
  explicit CalSlots(std::string dir);

  /// Installs `file`; returns the slot now active. Throws CalFileError (active slot unchanged).
  char Install(const CalFile& file);
  /// Verifies the calibration file at `path` (CRC, schema, loader) and installs it. A corrupt,
  /// truncated or NaN-bearing file throws CalFileError naming it; the active slot is unchanged.
  char InstallFromPath(const std::string& path);

  /// The active slot's letter ('A', 'B'), or 0 when nothing was installed yet.
  [[nodiscard]] char active() const;
  /// Loads the active calibration. When it is unreadable, falls back to the other slot and
  /// says why in *note (empty otherwise); *slot gets the slot used. Throws CalFileError if
  /// neither slot holds a valid calibration.
  [[nodiscard]] CalFile LoadActive(char* slot, std::string* note) const;

  [[nodiscard]] std::string SlotPath(char slot) const;

 private:
  std::string dir_;
};

}  // namespace ftstack::cal
