// The one error type of camhead's configuration readers (scenes, lens
// profiles, boards, lens traces, calibration measurements). Every reader
// names the file, the line where lines mean something (CSV), and the field,
// so that a mistake made by hand on set can be found without a debugger:
//
//   what() == "FILE: FIELD: REASON"        (JSON, and problems of a whole file)
//   what() == "FILE:LINE: FIELD: REASON"   (a line of a CSV file)
//
// A field is a JSON path ("lens.sources[1].port"), a CSV column ("t_s"), or
// a pseudo-field in parentheses for what is no field: "(file)" when the file
// cannot be read, "(JSON)" for a syntax error, "(top level)" for the root
// value. Outside the readers an empty field is allowed ("FILE: REASON"), for
// problems of a whole file found later (a trace that cannot be replayed).
//
// Each module keeps its own error class (SceneError, ProfileError, ...)
// derived from this one, so that its callers can tell whose file it was.
#pragma once

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace camhead::base {

class ConfigError : public std::runtime_error {
public:
  ConfigError(std::string file, std::string field, std::string reason);
  // line > 0: a line of the file; 0: the file as a whole, as above.
  ConfigError(std::string file, int line, std::string field, std::string reason);

  [[nodiscard]] const std::string &file() const { return file_; }
  [[nodiscard]] int line() const { return line_; }
  [[nodiscard]] const std::string &field() const { return field_; }
  [[nodiscard]] const std::string &reason() const { return reason_; }

private:
  std::string file_;
  int line_ = 0;
  std::string field_, reason_;
};

// Larger than any configuration file, lens trace or calibration a rig
// writes (an hour of a 1 kHz trace is about 150 MB).
inline constexpr std::size_t kMaxConfigFileBytes = std::size_t(256) << 20;

// The whole text of a configuration file (input_file.h). Throws ConfigError
// on the field "(file)": "cannot be opened: REASON", "is a folder, not a
// file", "is larger than 256 MiB", "cannot be read: REASON".
[[nodiscard]] std::string read_config_file(const std::filesystem::path &path);

} // namespace camhead::base
