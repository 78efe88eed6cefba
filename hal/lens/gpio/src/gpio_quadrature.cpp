// GPIO quadrature config checks and the factory. See gpio_quadrature.h.
#include "camhead/hal/lens/gpio/gpio_quadrature.h"

#include <stdexcept>
#include <utility>
#include <vector>

#include "gpiod_edge_source.h"

namespace camhead::hal::lens::gpio {
namespace {

struct NamedAxis {
  const char *name;
  LensAxis axis;
  const std::optional<GpioQuadratureAxis> *spec;
};

std::vector<NamedAxis> named_axes(const GpioQuadratureConfig &config) {
  return {{"focus", LensAxis::focus, &config.focus},
          {"iris", LensAxis::iris, &config.iris},
          {"zoom", LensAxis::zoom, &config.zoom}};
}

} // namespace

std::string validate(const GpioQuadratureConfig &config) {
  if (config.chip.empty()) {
    return "gpio quadrature: chip is empty; name a chip (gpiochip0), a path, a number or a label";
  }
  const std::string who = "gpio " + config.chip + ": ";
  if (config.reopen_interval.count() <= 0) {
    return who + "reopen_interval is " + std::to_string(config.reopen_interval.count()) +
           " ms; it must be > 0";
  }

  std::vector<std::pair<unsigned, std::string>> used; // offset, field
  const auto claim = [&](unsigned offset, std::string field) -> std::string {
    for (const auto &[other, other_field] : used) {
      if (other == offset) {
        return who + field + ' ' + std::to_string(offset) + " is already " + other_field;
      }
    }
    used.emplace_back(offset, std::move(field));
    return {};
  };

  bool any = false;
  for (const NamedAxis &n : named_axes(config)) {
    if (!n.spec->has_value()) {
      continue;
    }
    any = true;
    const GpioQuadratureAxis &a = **n.spec;
    const std::string prefix = std::string(n.name) + '.';
    std::string error = claim(a.line_a, prefix + "line_a");
    if (error.empty()) {
      error = claim(a.line_b, prefix + "line_b");
    }
    if (error.empty() && a.line_index) {
      error = claim(*a.line_index, prefix + "line_index");
    }
    if (!error.empty()) {
      return error;
    }
    if (!a.line_index && a.decoder.counts_at_index) {
      return who + prefix + "decoder.counts_at_index is set but " + prefix +
             "line_index is not: homing needs an index line";
    }
    if (!a.line_index && a.decoder.index_gate != IndexGate::any) {
      return who + prefix + "decoder.index_gate is set but " + prefix + "line_index is not";
    }
  }
  if (!any) {
    return who + "no axis configured; set at least one of focus, iris, zoom";
  }
  return {};
}

std::unique_ptr<QuadratureEncoder> open_gpio_quadrature(const GpioQuadratureConfig &config) {
  if (std::string error = validate(config); !error.empty()) {
    throw std::invalid_argument(error);
  }
  AxisConfigs decoders{};
  for (const NamedAxis &n : named_axes(config)) {
    if (n.spec->has_value()) {
      decoders[static_cast<std::size_t>(n.axis)] = (*n.spec)->decoder;
    }
  }
  QuadratureEncoderOptions options;
  options.reopen_interval = config.reopen_interval;
  options.resync_when_idle = config.resync_when_idle;
  options.require_device_at_start = true;
  return std::make_unique<QuadratureEncoder>(std::make_unique<detail::GpiodEdgeSource>(config),
                                             decoders, options);
}

} // namespace camhead::hal::lens::gpio
