#include "measurement/recording.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "measurement/wrench.hpp"

namespace ftstack {
namespace {

[[noreturn]] void Fail(const std::string& path, std::size_t line, std::size_t col,
                       const std::string& why) {
  throw RecordingError(path + ":" + std::to_string(line) + ":" + std::to_string(col) + ": " + why);
}

std::string Trim(std::string_view s) {
  std::size_t a = 0;
  std::size_t b = s.size();
  while (a < b && (s[a] == ' ' || s[a] == '\t' || s[a] == '\r')) ++a;
  while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t' || s[b - 1] == '\r')) --b;
  return std::string(s.substr(a, b - a));
}

void AppendNumber(std::string& out, double v) {
  char buf[32];
  const int n = std::snprintf(buf, sizeof buf, "%.10g", v);
  out.append(buf, static_cast<std::size_t>(n));
}

}  // namespace

int Recording::Find(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return static_cast<int>(i);
  }
  return -1;
}

const std::vector<double>& Recording::Column(const std::string& name) const {
  const int i = Find(name);
  if (i < 0) throw RecordingError(path + ": no column '" + name + "'");
  return columns[static_cast<std::size_t>(i)];
}

std::vector<double>& Recording::Column(const std::string& name) {
  const int i = Find(name);
  if (i < 0) throw RecordingError(path + ": no column '" + name + "'");
  return columns[static_cast<std::size_t>(i)];
}

std::size_t Recording::BridgeCount() const {
  std::size_t n = 0;
  while (Has("b" + std::to_string(n))) ++n;
  return n;
}

void Recording::SetColumn(const std::string& name, std::vector<double> values) {
  const int i = Find(name);
  if (i >= 0) {
    columns[static_cast<std::size_t>(i)] = std::move(values);
  } else {
    names.push_back(name);
    columns.push_back(std::move(values));
  }
}

std::string Recording::Meta(const std::string& key) const {
  for (const auto& m : metadata) {
    const auto colon = m.find(':');
    if (colon != std::string::npos && Trim(m.substr(0, colon)) == key) {
      return Trim(m.substr(colon + 1));
    }
  }
  return "";
}

const std::vector<std::string>& WrenchColumns() {
  static const std::vector<std::string> kNames(kWrenchAxisNames.begin(), kWrenchAxisNames.end());
  return kNames;
}

std::vector<std::string> BridgeColumns(std::size_t n) {
  std::vector<std::string> v;
  for (std::size_t i = 0; i < n; ++i) v.push_back("b" + std::to_string(i));
  return v;
}

namespace {

/// The line-by-line reader behind ParseRecording and ReadRecording: metadata, header, then one
/// row per line (lines are given without their '\n').
class LineParser {
 public:
  LineParser(const std::string& path, const ReadOptions& options) : options_(options) {
    rec_.path = path;
  }

  void Line(std::string_view line) {
    ++line_no_;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (!have_header_) {
      Header(line);
      return;
    }
    if (line.empty()) return;  // tolerate blank lines (e.g. a trailing one)
    Row(line);
  }

  Recording Finish() {
    if (!have_header_) throw RecordingError(rec_.path + ": no header line");
    return std::move(rec_);
  }

 private:
  void Header(std::string_view line) {
    const std::string& path = rec_.path;
    if (line.empty()) return;
    if (line[0] == '#') {
      rec_.metadata.push_back(Trim(line.substr(1)));
      return;
    }
    std::size_t a = 0;
    while (true) {
      const std::size_t b = line.find(',', a);
      const std::string name = Trim(line.substr(a, b == std::string_view::npos ? b : b - a));
      if (name.empty()) Fail(path, line_no_, a + 1, "empty column name in header");
      if (rec_.Find(name) >= 0) Fail(path, line_no_, a + 1, "duplicate column '" + name + "'");
      rec_.names.push_back(name);
      if (b == std::string_view::npos) break;
      a = b + 1;
    }
    rec_.columns.resize(rec_.names.size());
    have_header_ = true;
    auto require = [&](const std::string& col) {
      if (rec_.Find(col) < 0) {
        Fail(path, line_no_, line.size() + 1, "header lacks required column '" + col + "'");
      }
    };
    for (const auto& r : options_.required) require(r);
    if (options_.require_wrench) {
      for (const auto& r : WrenchColumns()) require(r);
    }
    if (options_.require_bridges) require("b0");
    t_col_ = rec_.Find("t");
  }

  void Row(std::string_view line) {
    const std::string& path = rec_.path;
    std::size_t a = 0;
    std::size_t field = 0;
    while (true) {
      const std::size_t b = line.find(',', a);
      const std::size_t stop = b == std::string_view::npos ? line.size() : b;
      if (field >= rec_.names.size()) {
        Fail(path, line_no_, a + 1,
             "more fields than the header's " + std::to_string(rec_.names.size()) + " columns");
      }
      std::size_t s = a;
      std::size_t e = stop;
      while (s < e && (line[s] == ' ' || line[s] == '\t')) ++s;
      while (e > s && (line[e - 1] == ' ' || line[e - 1] == '\t')) --e;
      double v = 0.0;
      const char* first = line.data() + s;
      const char* last = line.data() + e;
      if (s < e && *first == '+') ++first;
      const auto res = std::from_chars(first, last, v);
      if (s == e || res.ec != std::errc() || res.ptr != last) {
        Fail(path, line_no_, s + 1,
             "column '" + rec_.names[field] + "': '" + std::string(line.substr(s, e - s)) +
                 "' is not a number");
      }
      if (!std::isfinite(v)) {
        Fail(path, line_no_, s + 1,
             "column '" + rec_.names[field] + "': NaN/infinity is not allowed");
      }
      rec_.columns[field].push_back(v);
      ++field;
      if (b == std::string_view::npos) break;
      a = b + 1;
    }
    if (field != rec_.names.size()) {
      Fail(path, line_no_, line.size() + 1,
           "row has " + std::to_string(field) + " fields, header has " +
               std::to_string(rec_.names.size()));
    }
    rec_.data_lines.push_back(line_no_);
    if (t_col_ >= 0) CheckTime(line);
  }

  void CheckTime(std::string_view line) const {
    const auto& t = rec_.columns[static_cast<std::size_t>(t_col_)];
    if (t.size() >= 2 && !(t[t.size() - 1] > t[t.size() - 2])) {
      // Column of the t field within this line.
      std::size_t col = 1;
      std::size_t k = 0;
      for (std::size_t i = 0; i < line.size() && k < static_cast<std::size_t>(t_col_); ++i) {
        if (line[i] == ',') {
          ++k;
          col = i + 2;
        }
      }
      Fail(rec_.path, line_no_, col, "t is not strictly increasing");
    }
  }

  const ReadOptions& options_;
  Recording rec_;
  std::size_t line_no_ = 0;
  bool have_header_ = false;
  int t_col_ = -1;
};

/// Calls options.progress every ~1 MB of input (`done` = offset of the line being read).
class ProgressTicker {
 public:
  ProgressTicker(const ReadOptions& options, std::size_t total)
      : options_(options), total_(total) {}
  void At(std::size_t done) {
    if (options_.progress != nullptr && done >= next_) {
      options_.progress(done, total_, options_.progress_user);
      next_ = done + (1 << 20);
    }
  }

 private:
  const ReadOptions& options_;
  std::size_t total_;
  std::size_t next_ = 1 << 20;
};

}  // namespace

Recording ParseRecording(const std::string& text, const std::string& path,
                         const ReadOptions& options) {
  LineParser parser(path, options);
  ProgressTicker ticker(options, text.size());
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    ticker.At(pos);
    parser.Line(std::string_view(text.data() + pos, end - pos));
    pos = end + 1;
  }
  return parser.Finish();
}

Recording ReadRecording(const std::string& path, const ReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw RecordingError(path + ": cannot open: " + std::generic_category().message(errno));
  std::error_code ec;
  const bool regular = std::filesystem::is_regular_file(path, ec);
  std::streamoff size = -1;
  if (regular) {
    in.seekg(0, std::ios::end);
    size = in.tellg();
  }
  if (size < 0) {  // not a seekable regular file (a pipe, a directory): read it as a stream
    in.clear();
    std::stringstream ss;
    ss << in.rdbuf();
    return ParseRecording(ss.str(), path, options);
  }
  in.seekg(0, std::ios::beg);
  // Streamed in chunks (memory: the columns, not the text): lines are cut at '\n'; a line that
  // runs past the chunk's end is carried to the front of the next one.
  LineParser parser(path, options);
  ProgressTicker ticker(options, static_cast<std::size_t>(size));
  std::vector<char> buf(std::size_t{1} << 20);
  std::size_t kept = 0;    // bytes of an unfinished line at the front of buf
  std::size_t offset = 0;  // file offset of buf[0]
  while (true) {
    if (kept == buf.size()) buf.resize(buf.size() * 2);  // a line longer than the buffer
    in.read(buf.data() + kept, static_cast<std::streamsize>(buf.size() - kept));
    const auto got = static_cast<std::size_t>(in.gcount());
    if (got == 0 && in.bad()) {
      throw RecordingError(path + ": read failed: " + std::generic_category().message(errno));
    }
    const std::size_t have = kept + got;
    const bool eof = got == 0;
    std::size_t pos = 0;
    while (pos < have) {
      const void* nl = std::memchr(buf.data() + pos, '\n', have - pos);
      if (nl == nullptr && !eof) break;
      const std::size_t end =
          nl == nullptr ? have
                        : static_cast<std::size_t>(static_cast<const char*>(nl) - buf.data());
      ticker.At(offset + pos);
      parser.Line(std::string_view(buf.data() + pos, end - pos));
      pos = end + 1;
    }
    if (eof) break;
    kept = have - pos;
    std::memmove(buf.data(), buf.data() + pos, kept);
    offset += pos;
  }
  return parser.Finish();
}

void CheckAligned(const Recording& sim, const Recording& real) {
  if (sim.rows() != real.rows()) {
    throw RecordingError(sim.path + ": has " + std::to_string(sim.rows()) + " rows but " +
                         real.path + " has " + std::to_string(real.rows()));
  }
  const auto& ts = sim.Column("t");
  const auto& tr = real.Column("t");
  for (std::size_t i = 0; i < ts.size(); ++i) {
    if (std::fabs(ts[i] - tr[i]) > 1e-6) {
      const int col = sim.Find("t");
      throw RecordingError(sim.path + ":" +
                           std::to_string(sim.data_lines.empty() ? i + 2 : sim.data_lines[i]) +
                           ":" + std::to_string(col + 1) + ": t = " + std::to_string(ts[i]) +
                           " does not match " + real.path + " (t = " + std::to_string(tr[i]) + ")");
    }
  }
}

void WriteRecording(const std::string& path, const Recording& rec) {
  std::vector<std::string> meta = rec.metadata;
  RecordingWriter w(path, meta, rec.names);
  std::vector<double> row(rec.names.size());
  for (std::size_t i = 0; i < rec.rows(); ++i) {
    for (std::size_t c = 0; c < rec.names.size(); ++c) row[c] = rec.columns[c][i];
    w.WriteRow(row);
  }
}

RecordingWriter::RecordingWriter(const std::string& path, const std::vector<std::string>& metadata,
                                 const std::vector<std::string>& names)
    : path_(path), width_(names.size()) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) {
    throw RecordingError(path + ": cannot write: " + std::generic_category().message(errno));
  }
  std::string head;
  for (const auto& m : metadata) {
    head.append("# ");
    head.append(m);
    head.push_back('\n');
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) head.push_back(',');
    head.append(names[i]);
  }
  head.push_back('\n');
  std::fputs(head.c_str(), file_);
}

RecordingWriter::~RecordingWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void RecordingWriter::WriteRow(const std::vector<double>& values) {
  if (values.size() != width_) {
    throw RecordingError(path_ + ": row of " + std::to_string(values.size()) + " values for " +
                         std::to_string(width_) + " columns");
  }
  line_.clear();
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) line_ += ',';
    AppendNumber(line_, values[i]);
  }
  line_ += '\n';
  if (std::fwrite(line_.data(), 1, line_.size(), file_) != line_.size()) {
    throw RecordingError(path_ + ": write failed: " + std::generic_category().message(errno));
  }
}

void RecordingWriter::Flush() { std::fflush(file_); }

}  // namespace ftstack
