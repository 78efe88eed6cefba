#include "pose_trace.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "camhead/base/config_csv.h"
#include "camhead/base/config_error.h"
#include "tracker_axes.h"

namespace camhead::pipeline {
namespace {

constexpr std::string_view kFirstLine = "# camhead pose trace v1";
const std::vector<std::string_view> kColumns = {"t_s",     "x_m",      "y_m",     "z_m",
                                                "pan_deg", "tilt_deg", "roll_deg"};

} // namespace

CameraPose pose_of_row(double x_m, double y_m, double z_m, double pan_deg, double tilt_deg,
                       double roll_deg) {
  // A camera head's axes are FreeD's (tracker_axes.h); its stage is the
  // world turned: X = x, Y = -z, Z = y.
  return from_freed({.x_m = x_m,
                     .y_m = -z_m,
                     .z_m = y_m,
                     .pan_deg = pan_deg,
                     .tilt_deg = tilt_deg,
                     .roll_deg = roll_deg});
}

PoseTrace::PoseTrace(std::vector<Row> rows) : rows_(std::move(rows)) {}

CameraPose PoseTrace::at(std::int64_t t_ns) const {
  const std::int64_t first = rows_.front().t_ns, period = rows_.back().t_ns - first;
  std::int64_t t = (t_ns - first) % period;
  if (t < 0)
    t += period;
  t += first;
  const auto after = std::upper_bound(rows_.begin(), rows_.end(), t,
                                      [](std::int64_t v, const Row &r) { return v < r.t_ns; });
  const Row &b = *std::min(after, rows_.end() - 1);
  const Row &a = *(&b - 1);
  const double u = std::clamp(double(t - a.t_ns) / double(b.t_ns - a.t_ns), 0.0, 1.0);
  const glm::dquat to = glm::dot(a.pose.orientation, b.pose.orientation) < 0.0 ? -b.pose.orientation
                                                                               : b.pose.orientation;
  return {a.pose.position + u * (b.pose.position - a.pose.position),
          glm::normalize(glm::slerp(a.pose.orientation, to, u))};
}

PoseTrace parse_pose_trace(std::string_view text, const std::filesystem::path &file) {
  try {
    base::CsvReader csv(file.string(), text);
    const std::optional<std::string_view> first = csv.next_line();
    if (!first || *first != kFirstLine)
      csv.fail("format", "the first line must be \"" + std::string(kFirstLine) + "\"");
    csv.read_header(kColumns, "t_s,x_m,y_m,z_m,pan_deg,tilt_deg,roll_deg");
    for (const std::string_view column : kColumns)
      csv.require_column(column, "a pose trace gives every row a whole pose");
    std::vector<PoseTrace::Row> rows;
    const base::Range position = base::Range::within(-10000.0, 10000.0);
    const base::Range angle = base::Range::within(-360.0, 360.0);
    while (const std::optional<base::CsvRow> row = csv.next_row()) {
      const double t = csv.number(csv.cell(*row, "t_s"), "t_s", base::Range::within(0.0, 1e6));
      const std::int64_t t_ns = std::llround(t * 1e9);
      if (!rows.empty() && t_ns <= rows.back().t_ns)
        csv.fail("t_s", "must be later than the row before (" +
                            std::to_string(double(rows.back().t_ns) * 1e-9) + " s)");
      const auto value = [&](std::string_view name, const base::Range &range) {
        return csv.number(csv.cell(*row, name), name, range);
      };
      rows.push_back({t_ns, pose_of_row(value("x_m", position), value("y_m", position),
                                        value("z_m", position), value("pan_deg", angle),
                                        value("tilt_deg", base::Range::within(-90.0, 90.0)),
                                        value("roll_deg", angle))});
    }
    if (rows.size() < 2)
      throw PoseTraceError(file.string(), "(rows)",
                           "a path needs at least two rows (a camera that stands still is a "
                           "static pose)");
    return PoseTrace(std::move(rows));
  } catch (const PoseTraceError &) {
    throw;
  } catch (const base::ConfigError &e) {
    throw PoseTraceError(e);
  }
}

PoseTrace load_pose_trace(const std::filesystem::path &file) {
  std::string text;
  try {
    text = base::read_config_file(file); // bounded; a folder refused
  } catch (const base::ConfigError &e) {
    throw PoseTraceError(e);
  }
  return parse_pose_trace(text, file);
}

} // namespace camhead::pipeline
