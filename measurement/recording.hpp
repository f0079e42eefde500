// Recordings (docs/spec/recording-format.md): read and write by column name, errors at line:column.
#pragma once

#include <cstddef>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace ftstack {

/// A malformed recording. what() is "FILE:LINE:COLUMN: reason" (line and column 1-based; column
/// counts characters) or "FILE: reason" when no position applies.
class RecordingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A recording held column-major: columns[i] is named names[i].
struct Recording {
  std::string path;                   ///< where it came from (for messages)
  std::vector<std::string> metadata;  ///< "# key: value" lines before the header, without "# "
  std::vector<std::string> names;     ///< header, in file order
  std::vector<std::vector<double>> columns;
  std::vector<std::size_t> data_lines;  ///< file line number of each row (1-based)

  [[nodiscard]] std::size_t rows() const { return columns.empty() ? 0 : columns[0].size(); }
  /// Index of a column, or -1.
  [[nodiscard]] int Find(const std::string& name) const;
  [[nodiscard]] bool Has(const std::string& name) const { return Find(name) >= 0; }
  /// The column named `name`; throws RecordingError naming the file if it is absent.
  [[nodiscard]] const std::vector<double>& Column(const std::string& name) const;
  [[nodiscard]] std::vector<double>& Column(const std::string& name);
  /// Number of bridge columns b0, b1, … present without a gap.
  [[nodiscard]] std::size_t BridgeCount() const;
  /// Appends (or replaces) a column.
  void SetColumn(const std::string& name, std::vector<double> values);
  /// Value of metadata key `key` ("" if absent).
  [[nodiscard]] std::string Meta(const std::string& key) const;
};

/// What a reader requires of a file.
struct ReadOptions {
  std::vector<std::string> required;  ///< columns that must exist (e.g. "t", "Fx", …)
  bool require_bridges = false;       ///< at least b0 must exist
  bool require_wrench = false;        ///< Fx Fy Fz Mx My Mz must exist
  /// Called with (bytes read, total bytes) every ~1 MB, for progress bars. May be empty.
  void (*progress)(std::size_t done, std::size_t total, void* user) = nullptr;
  void* progress_user = nullptr;
};

/// Reads a recording. Refuses (RecordingError with file:line:column) a missing required column,
/// a field that is not a finite number (NaN and infinity are errors), a row with the wrong number
/// of fields, and a `t` column that does not strictly increase.
[[nodiscard]] Recording ReadRecording(const std::string& path, const ReadOptions& options = {});
/// The same from text already in memory; `path` only names it in messages.
[[nodiscard]] Recording ParseRecording(const std::string& text, const std::string& path,
                                       const ReadOptions& options = {});

/// Checks that a simulation lines up with a real recording: same row count and |Δt| ≤ 1e-6 s.
/// Throws RecordingError naming the simulation file and the first line that differs.
void CheckAligned(const Recording& sim, const Recording& real);

/// The wrench column names in order: Fx Fy Fz Mx My Mz.
[[nodiscard]] const std::vector<std::string>& WrenchColumns();
/// "b0" … "b{n-1}".
[[nodiscard]] std::vector<std::string> BridgeColumns(std::size_t n);

/// Writes a whole recording (columns in stored order). Numbers with up to 10 significant digits.
void WriteRecording(const std::string& path, const Recording& rec);

/// Streaming writer for long recordings (the daemon's --log): header once, then rows.
class RecordingWriter {
 public:
  /// Opens `path` for writing; throws RecordingError if it cannot.
  RecordingWriter(const std::string& path, const std::vector<std::string>& metadata,
                  const std::vector<std::string>& names);
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;
  /// Writes one row; values.size() must equal the number of columns.
  void WriteRow(const std::vector<double>& values);
  void Flush();

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
  std::size_t width_ = 0;
  std::string line_;
};

}  // namespace ftstack
