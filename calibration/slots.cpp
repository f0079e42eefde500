#include "calibration/slots.hpp"

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
  const char current = active();
  const char target = current == 'A' ? 'B' : 'A';
  const std::string path = SlotPath(target);
  SaveCalFile(path, file);  // refuses (throws) before writing if the loader rejects it
  (void)LoadCalFile(path);  // read back: what is on disk must verify
  WriteFileAtomic((std::filesystem::path(dir_) / "active").string(), std::string(1, target) + "\n");
  return target;
}

char CalSlots::InstallFromPath(const std::string& path) { return Install(LoadCalFile(path)); }

CalFile CalSlots::LoadActive(char* slot, std::string* note) const {
  note->clear();
  const char current = active();
  if (current == 0) throw CalFileError(dir_ + ": no calibration installed");
  try {
    *slot = current;
    return LoadCalFile(SlotPath(current));
  } catch (const CalFileError& e) {
    const char other = current == 'A' ? 'B' : 'A';
    *note = std::string("active slot ") + current + " refused (" + e.what() +
            "); using the previous calibration in slot " + other;
    try {
      *slot = other;
      return LoadCalFile(SlotPath(other));
    } catch (const CalFileError& e2) {
      throw CalFileError(*note + ", which is refused too: " + e2.what());
    }
  }
}

}  // namespace ftstack::cal
