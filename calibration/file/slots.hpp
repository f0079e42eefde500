// Two calibration slots (A/B) on the device with atomic replacement and fallback to the previous
// one.
#pragma once

#include <string>

#include "calibration/file/cal_file.hpp"

namespace ftstack::cal {

/// A directory holding cal_A.json, cal_B.json and `active` (one line: "A" or "B"). A new
/// calibration is verified, written into the inactive slot (temporary file, fsync, rename),
/// read back and verified again, and only then made active by replacing `active` atomically.
/// A refused file never touches the active slot. If the active slot is found corrupt when
/// loading, the other slot (the previous calibration) is used and the reason reported; if
/// `active` itself is missing or unreadable, the slot file written last is taken. Every step of
/// Install is a crash-injection point (FTSTACK_CRASH_AT, see CrashPoint); a crash at any of them
/// leaves exactly one valid calibration that LoadActive (and so ftd --cal-dir) uses.
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
  /// The slot `active` records; when that record is missing or unreadable, the slot file
  /// written last (and *note says so); 0 when neither slot file exists.
  [[nodiscard]] char Recorded(std::string* note) const;
  /// The slot LoadActive would use (the recorded one, or the other when it is refused).
  [[nodiscard]] char InUse() const;

  std::string dir_;
};

}  // namespace ftstack::cal
