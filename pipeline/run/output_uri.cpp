#include "output_uri.h"

#include "camhead/base/path_text.h"
#include "camhead/hal/video_file/frame_pattern.h"

namespace camhead::pipeline {
namespace {

constexpr std::string_view kForms =
    "(v4l2:/dev/videoN, drm:CARD[:CONNECTOR], file:PATH.y4m, file:DIR/%05d.png or null)";

// drm:CARD[:CONNECTOR][?mode=WxH[@Hz]]
void take_drm(std::string_view uri, std::string_view rest, OutputSpec &spec) {
  if (const std::size_t q = rest.find('?'); q != std::string_view::npos) {
    const std::string_view option = rest.substr(q + 1);
    constexpr std::string_view kKey = "mode=";
    if (option.substr(0, kKey.size()) != kKey || option.size() == kKey.size())
      throw OutputError(uri, "unknown option \"" + std::string(option) +
                                 "\" (only mode=WxH or mode=WxH@Hz)");
    spec.mode = std::string(option.substr(kKey.size()));
    rest = rest.substr(0, q);
  }
  const std::size_t colon = rest.find(':');
  spec.target = std::string(rest.substr(0, colon));
  if (colon != std::string_view::npos) {
    spec.connector = std::string(rest.substr(colon + 1));
    if (spec.connector.empty())
      throw OutputError(uri, "connector: empty (drm:CARD:CONNECTOR, e.g. drm:card0:HDMI-A-1)");
  }
}

bool ends_with(std::string_view s, std::string_view tail) {
  return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail;
}

// Splits "TARGET?format=F" and sets spec.format from F (yuyv or nv12).
std::string_view take_format(std::string_view uri, std::string_view rest, OutputSpec &spec) {
  const std::size_t q = rest.find('?');
  if (q == std::string_view::npos)
    return rest;
  const std::string_view option = rest.substr(q + 1);
  constexpr std::string_view kKey = "format=";
  if (option.substr(0, kKey.size()) != kKey)
    throw OutputError(uri,
                      "unknown option \"" + std::string(option) + "\" (only format=yuyv|nv12)");
  const std::string_view name = option.substr(kKey.size());
  if (name == "yuyv")
    spec.format = base::PixelFormat::yuyv;
  else if (name == "nv12")
    spec.format = base::PixelFormat::nv12;
  else
    throw OutputError(uri, "format: \"" + std::string(name) + "\" is not yuyv or nv12");
  return rest.substr(0, q);
}

} // namespace

OutputSpec parse_output_uri(std::string_view uri) {
  OutputSpec spec;
  spec.uri = std::string(uri);
  if (const std::string problem = base::path_text_problem(uri); !problem.empty())
    throw OutputError(base::printable_text(uri), problem);
  if (uri == "null") {
    spec.kind = OutputKind::null;
    return spec;
  }
  const std::size_t colon = uri.find(':');
  if (colon == std::string_view::npos || colon + 1 == uri.size())
    throw OutputError(uri, "not an output URI " + std::string(kForms));
  const std::string_view scheme = uri.substr(0, colon);
  std::string_view rest = uri.substr(colon + 1);
  if (scheme == "v4l2") {
    spec.kind = OutputKind::v4l2;
    spec.target = std::string(take_format(uri, rest, spec));
  } else if (scheme == "drm") {
    spec.kind = OutputKind::drm;
    spec.format = base::PixelFormat::xrgb8888;
    take_drm(uri, rest, spec);
  } else if (scheme == "file") {
    if (ends_with(rest.substr(0, rest.find('?')), ".y4m")) {
      spec.kind = OutputKind::y4m;
      spec.target = std::string(take_format(uri, rest, spec));
    } else if (ends_with(rest, ".png")) {
      spec.kind = OutputKind::png;
      spec.format = base::PixelFormat::rgb24;
      spec.target = std::string(rest);
      if (spec.target.find('%') == std::string::npos)
        throw OutputError(uri, "a PNG sequence needs a frame number in its name, e.g. "
                               "file:frames/%05d.png");
      std::string error;
      if (!hal::video_file::FramePattern::parse(spec.target, error))
        throw OutputError(uri, "pattern: " + error);
    } else {
      throw OutputError(uri, "a file output is PATH.y4m or DIR/%05d.png");
    }
  } else {
    throw OutputError(uri, "unknown output \"" + std::string(scheme) + "\" " + std::string(kForms));
  }
  if (spec.target.empty())
    throw OutputError(uri, "names no device or file");
  return spec;
}

std::vector<OutputSpec> parse_output_uris(const std::vector<std::string> &uris) {
  std::vector<OutputSpec> specs;
  for (const std::string &uri : uris) {
    OutputSpec spec = parse_output_uri(uri);
    for (const OutputSpec &earlier : specs)
      if (spec.kind == OutputKind::drm && earlier.kind == OutputKind::drm &&
          spec.target == earlier.target && spec.connector == earlier.connector)
        throw OutputError(uri, "drives " + spec.target + " as " + earlier.uri +
                                   " does; give each output its own connector");
    specs.push_back(std::move(spec));
  }
  return specs;
}

} // namespace camhead::pipeline
