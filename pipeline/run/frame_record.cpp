#include "frame_record.h"

#include <cinttypes>
#include <cmath>

namespace camhead::pipeline {

void write_filler_record(std::FILE *out, std::uint64_t output_frame, const char *kind,
                         std::int64_t output_ns) {
  std::fprintf(out, "{\"output_frame\":%" PRIu64 ",\"kind\":\"%s\",\"output_ns\":%" PRId64 "}\n",
               output_frame, kind, output_ns);
  std::fflush(out); // a line as each frame goes out, for `tail -f` or a FIFO's reader
}

std::string json_string(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char code[8];
      std::snprintf(code, sizeof code, "\\u%04x", unsigned(c));
      out += code;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

void write_composite_record(std::FILE *out, std::uint64_t output_frame, const FrameRecord &r,
                            std::int64_t output_ns, const RunRecordFields &run) {
  // JSON has no NaN: a pose not found in the frame, a tracking time not known.
  char reprojection[32] = "null", track_ms[32] = "null";
  if (std::isfinite(r.reprojection_px))
    std::snprintf(reprojection, sizeof reprojection, "%.4f", r.reprojection_px);
  if (std::isfinite(r.track_s))
    std::snprintf(track_ms, sizeof track_ms, "%.3f", 1e3 * r.track_s);
  std::fprintf(
      out,
      "{\"output_frame\":%" PRIu64 ",\"kind\":\"composite\",\"sequence\":%" PRIu64
      ",\"setup\":%" PRIu64 ",\"capture_ns\":%" PRId64 ",\"exposure_mid_ns\":%" PRId64
      ",\"delivered_ns\":%" PRId64 ",\"render_start_ns\":%" PRId64 ",\"render_end_ns\":%" PRId64
      ",\"output_ns\":%" PRId64 ",\"focus_m\":%s,\"f_number\":%.6g"
      ",\"focal_length_mm\":%.6g,\"lens_fresh\":%s,\"lens_wait_ms\":%.3f,\"rpp\":%.6g"
      ",\"camera_rays\":%" PRIu64 ",\"history_samples\":%u,\"reprojected_samples\":%" PRIu64
      ",\"traced\":%.4f,\"dropped_before\":%" PRIu64 ",\"decode_ms\":%.3f,\"trace_ms\":%.3f"
      ",\"rays_ms\":%.3f,\"encode_ms\":%.3f,\"executor\":%s,\"pose_source\":%s,\"pose_known\":%s,"
      "\"pose_fresh\":%s"
      ",\"pose\":{\"position\":[%.7g,%.7g,%.7g],\"forward\":[%.6g,%.6g,%.6g]"
      ",\"up\":[%.6g,%.6g,%.6g]},\"markers_seen\":%d,\"pose_found_by\":%s%s%s"
      ",\"reprojection_px\":%s"
      ",\"track_ms\":%s,\"pose_wait_ms\":%.3f}\n",
      output_frame, r.sequence, r.setup, r.capture_ns, r.exposure_mid_ns, r.delivered_ns,
      r.render_start_ns, r.render_end_ns, output_ns,
      std::isfinite(r.focus_m) ? std::to_string(r.focus_m).c_str() : "null", r.f_number,
      r.focal_length_mm, r.lens_fresh ? "true" : "false", 1e3 * r.lens_wait_s, r.rpp, r.camera_rays,
      r.history_samples, r.reprojected_samples, r.traced, r.dropped_before, 1e3 * r.decode_s,
      1e3 * r.trace_s, 1e3 * r.rays_s, 1e3 * r.encode_s, run.executor.c_str(),
      run.pose_source.c_str(), r.pose_known ? "true" : "false", r.pose_fresh ? "true" : "false",
      r.position.x, r.position.y, r.position.z, r.forward.x, r.forward.y, r.forward.z, r.up.x,
      r.up.y, r.up.z, r.markers_seen, r.pose_found_by ? "\"" : "",
      r.pose_found_by ? r.pose_found_by : "null", r.pose_found_by ? "\"" : "", reprojection,
      track_ms, 1e3 * r.pose_wait_s);
  std::fflush(out);
}

} // namespace camhead::pipeline
