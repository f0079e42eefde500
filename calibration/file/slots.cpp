#include "calibration/file/slots.hpp"

#include <filesystem>
#include <fstream>

namespace ftstack::cal {

CalSlots::CalSlots(std::string dir) : dir_(std::move(dir)) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw CalFileError(dir_ + ": cannot create the slot directory: " + ec.message());
}

std::string CalSlots::SlotPath(char slot) const {
  return (std::filesystem::path(dir_) / (std::string("cal_") + slot + ".json")).string();
}

char CalSlots::active() const {
  std::ifstream in(std::filesystem::path(dir_) / "active");
  std::string s;
  if (!(in >> s) || (s != "A" && s != "B")) return 0;
  return s[0];
}

char CalSlots::Install(const CalFile& file) {
  // The slot in use (as LoadActive resolves it, also with a lost `active` record) is never
  // written: the new calibration goes into the other one.
  const char current = InUse();
  const char target = current == 'A' ? 'B' : 'A';
  const std::string path = SlotPath(target);
  // Crash-injection points (FTSTACK_CRASH_AT, see CrashPoint): slot-write … slot-dirsync,
  // read-back, active-write … active-dirsync, done.
  const std::string text = ToJson(file).dump(2) + "\n";  // refuses (throws) before writing
  WriteFileAtomic(path, text, "slot");
  CrashPoint("read-back");
  (void)LoadCalFile(path);  // read back: what is on disk must verify
  WriteFileAtomic((std::filesystem::path(dir_) / "active").string(), std::string(1, target) + "\n",
                  "active");
  CrashPoint("done");
  return target;
}

char CalSlots::InUse() const {
  try {
    char slot = 0;
    std::string note;
    (void)LoadActive(&slot, &note);
    return slot;
  } catch (const CalFileError&) {
    return active();
  }
}

char CalSlots::Recorded(std::string* note) const {
  const char current = active();
  if (current != 0) return current;
  // The `active` record is missing or unreadable (lost, or torn by the storage): take the slot
  // file written last, as the last completed install wrote it after the other.
  namespace fs = std::filesystem;
  std::error_code ea;
  std::error_code eb;
  const auto ta = fs::last_write_time(SlotPath('A'), ea);
  const auto tb = fs::last_write_time(SlotPath('B'), eb);
  if (ea && eb) return 0;
  const char slot = ea ? 'B' : (eb ? 'A' : (tb > ta ? 'B' : 'A'));
  const bool tie = !ea && !eb && ta == tb;  // within one tick of the file system's clock
  *note = std::string("the active-slot record is missing or unreadable; taking slot ") + slot +
          (tie ? " (both slot files carry the same modification time: undecidable, A taken)"
               : " (written last)");
  return slot;
}

char CalSlots::InstallFromPath(const std::string& path) { return Install(LoadCalFile(path)); }

CalFile CalSlots::LoadActive(char* slot, std::string* note) const {
  note->clear();
  const char current = Recorded(note);
  if (current == 0) throw CalFileError(dir_ + ": no calibration installed");
  try {
    *slot = current;
    return LoadCalFile(SlotPath(current));
  } catch (const CalFileError& e) {
    const char other = current == 'A' ? 'B' : 'A';
    *note = (note->empty() ? "" : *note + "; ") + "active slot " + current + " refused (" +
            e.what() + "); using the previous calibration in slot " + other;
    try {
      *slot = other;
      return LoadCalFile(SlotPath(other));
    } catch (const CalFileError& e2) {
      throw CalFileError(*note + ", which is refused too: " + e2.what());
    }
  }
}

}  // namespace ftstack::cal
