// See drm_card.h.
#include "drm_card.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <utility>

#include <drm_fourcc.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace camhead::hal::output::drm {
namespace {

template <class T> std::uint64_t user_pointer(T *pointer) {
  return static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(pointer));
}

} // namespace

CardFile open_card(const std::string &path, std::string &error) {
  CardFile card = hal::open_device_node(path, O_RDWR | O_NONBLOCK, error);
  if (!card.is_open() && errno == ENOENT)
    error += " (is the display driver loaded? ls /dev/dri)";
  return card;
}

std::string driver_name(const CardFile &card) {
  std::array<char, 64> name{};
  drm_version version{};
  version.name = name.data();
  version.name_len = name.size() - 1;
  if (!card.ioctl(DRM_IOCTL_VERSION, version, true))
    return {};
  return std::string(name.data(), std::min<std::size_t>(version.name_len, name.size() - 1));
}

std::vector<std::string> list_cards() {
  std::vector<std::pair<int, std::string>> found;
  std::error_code ec;
  for (const auto &entry : std::filesystem::directory_iterator("/dev/dri", ec)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with("card") || name.size() == 4)
      continue;
    const std::string number = name.substr(4);
    if (!std::all_of(number.begin(), number.end(), [](char c) { return c >= '0' && c <= '9'; }))
      continue;
    found.emplace_back(std::stoi(number), entry.path().string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> paths;
  for (auto &[number, path] : found)
    paths.push_back(std::move(path));
  return paths;
}

std::optional<Resources> get_resources(const CardFile &card, std::string &error) {
  for (;;) {
    drm_mode_card_res counts{};
    if (!card.ioctl(DRM_IOCTL_MODE_GETRESOURCES, counts, true)) {
      error = "DRM_IOCTL_MODE_GETRESOURCES: " + errno_text(errno) +
              (errno == EOPNOTSUPP || errno == EINVAL ? " (not a mode-setting card)" : "");
      return std::nullopt;
    }
    Resources resources;
    std::vector<std::uint32_t> fbs(counts.count_fbs);
    resources.crtcs.resize(counts.count_crtcs);
    resources.connectors.resize(counts.count_connectors);
    resources.encoders.resize(counts.count_encoders);
    drm_mode_card_res res = counts;
    res.fb_id_ptr = user_pointer(fbs.data());
    res.crtc_id_ptr = user_pointer(resources.crtcs.data());
    res.connector_id_ptr = user_pointer(resources.connectors.data());
    res.encoder_id_ptr = user_pointer(resources.encoders.data());
    if (!card.ioctl(DRM_IOCTL_MODE_GETRESOURCES, res, true)) {
      error = "DRM_IOCTL_MODE_GETRESOURCES: " + errno_text(errno);
      return std::nullopt;
    }
    // A hotplug between the two calls: the kernel filled nothing past the
    // old counts, so ask again.
    if (res.count_fbs > counts.count_fbs || res.count_crtcs > counts.count_crtcs ||
        res.count_connectors > counts.count_connectors ||
        res.count_encoders > counts.count_encoders)
      continue;
    resources.crtcs.resize(res.count_crtcs);
    resources.connectors.resize(res.count_connectors);
    resources.encoders.resize(res.count_encoders);
    return resources;
  }
}

std::optional<Connector> get_connector(const CardFile &card, std::uint32_t id, bool probe,
                                       std::string &error) {
  // A count_modes of 0 is what makes the kernel probe; one mode's room
  // (filled or not) reads the cached state, as drmModeGetConnectorCurrent.
  drm_mode_modeinfo spare{};
  drm_mode_get_connector counts{};
  counts.connector_id = id;
  if (!probe) {
    counts.count_modes = 1;
    counts.modes_ptr = user_pointer(&spare);
  }
  if (!card.ioctl(DRM_IOCTL_MODE_GETCONNECTOR, counts, true)) {
    error = "DRM_IOCTL_MODE_GETCONNECTOR " + std::to_string(id) + ": " + errno_text(errno);
    return std::nullopt;
  }
  for (;;) {
    Connector connector;
    connector.encoders.resize(counts.count_encoders);
    connector.modes.resize(std::max<std::uint32_t>(counts.count_modes, 1));
    std::vector<std::uint32_t> props(counts.count_props);
    std::vector<std::uint64_t> values(counts.count_props);
    drm_mode_get_connector conn{};
    conn.connector_id = id;
    conn.count_encoders = counts.count_encoders;
    conn.encoders_ptr = user_pointer(connector.encoders.data());
    // Never 0 here: that would probe a second time.
    conn.count_modes = static_cast<std::uint32_t>(connector.modes.size());
    conn.modes_ptr = user_pointer(connector.modes.data());
    conn.count_props = counts.count_props;
    conn.props_ptr = user_pointer(props.data());
    conn.prop_values_ptr = user_pointer(values.data());
    if (!card.ioctl(DRM_IOCTL_MODE_GETCONNECTOR, conn, true)) {
      error = "DRM_IOCTL_MODE_GETCONNECTOR " + std::to_string(id) + ": " + errno_text(errno);
      return std::nullopt;
    }
    if (conn.count_encoders > counts.count_encoders || conn.count_modes > connector.modes.size() ||
        conn.count_props > counts.count_props) {
      counts = conn;
      continue;
    }
    connector.id = id;
    connector.type = conn.connector_type;
    connector.type_id = conn.connector_type_id;
    connector.connection = conn.connection;
    connector.encoder_id = conn.encoder_id;
    connector.encoders.resize(conn.count_encoders);
    connector.modes.resize(conn.count_modes);
    return connector;
  }
}

std::optional<drm_mode_get_encoder> get_encoder(const CardFile &card, std::uint32_t id,
                                                std::string &error) {
  drm_mode_get_encoder encoder{};
  encoder.encoder_id = id;
  if (!card.ioctl(DRM_IOCTL_MODE_GETENCODER, encoder, true)) {
    error = "DRM_IOCTL_MODE_GETENCODER " + std::to_string(id) + ": " + errno_text(errno);
    return std::nullopt;
  }
  return encoder;
}

std::optional<drm_mode_crtc> get_crtc(const CardFile &card, std::uint32_t id, std::string &error) {
  drm_mode_crtc crtc{};
  crtc.crtc_id = id;
  if (!card.ioctl(DRM_IOCTL_MODE_GETCRTC, crtc, true)) {
    error = "DRM_IOCTL_MODE_GETCRTC " + std::to_string(id) + ": " + errno_text(errno);
    return std::nullopt;
  }
  return crtc;
}

bool set_crtc(const CardFile &card, std::uint32_t crtc, std::uint32_t fb, std::uint32_t x,
              std::uint32_t y, std::span<const std::uint32_t> connectors,
              const drm_mode_modeinfo *mode, std::string &error) {
  drm_mode_crtc request{};
  request.crtc_id = crtc;
  request.fb_id = fb;
  request.x = x;
  request.y = y;
  request.set_connectors_ptr = user_pointer(connectors.data());
  request.count_connectors = static_cast<std::uint32_t>(connectors.size());
  if (mode != nullptr) {
    request.mode = *mode;
    request.mode_valid = 1;
  }
  if (!card.ioctl(DRM_IOCTL_MODE_SETCRTC, request, true)) {
    error = "DRM_IOCTL_MODE_SETCRTC: " + errno_text(errno);
    return false;
  }
  return true;
}

DumbBuffer::~DumbBuffer() {
  // release() needs the card; a buffer dropped without it only unmaps, and
  // the kernel frees the rest when the card is closed.
  if (map_ != nullptr)
    ::munmap(map_, size_);
}

DumbBuffer::DumbBuffer(DumbBuffer &&other) noexcept
    : handle_(std::exchange(other.handle_, 0)), fb_id_(std::exchange(other.fb_id_, 0)),
      pitch_(std::exchange(other.pitch_, 0)), map_(std::exchange(other.map_, nullptr)),
      size_(std::exchange(other.size_, 0)) {}

DumbBuffer &DumbBuffer::operator=(DumbBuffer &&other) noexcept {
  if (this != &other) {
    if (map_ != nullptr)
      ::munmap(map_, size_);
    handle_ = std::exchange(other.handle_, 0);
    fb_id_ = std::exchange(other.fb_id_, 0);
    pitch_ = std::exchange(other.pitch_, 0);
    map_ = std::exchange(other.map_, nullptr);
    size_ = std::exchange(other.size_, 0);
  }
  return *this;
}

std::optional<DumbBuffer> DumbBuffer::create(const CardFile &card, int width, int height,
                                             std::string &error) {
  DumbBuffer buffer;
  drm_mode_create_dumb create{};
  create.width = static_cast<std::uint32_t>(width);
  create.height = static_cast<std::uint32_t>(height);
  create.bpp = 32;
  if (!card.ioctl(DRM_IOCTL_MODE_CREATE_DUMB, create, true)) {
    error = "DRM_IOCTL_MODE_CREATE_DUMB " + std::to_string(width) + "x" + std::to_string(height) +
            ": " + errno_text(errno);
    return std::nullopt;
  }
  buffer.handle_ = create.handle;
  buffer.pitch_ = create.pitch;
  buffer.size_ = static_cast<std::size_t>(create.size);
  const auto fail = [&](std::string why) -> std::optional<DumbBuffer> {
    error = std::move(why);
    buffer.release(card);
    return std::nullopt;
  };

  drm_mode_fb_cmd2 fb{};
  fb.width = create.width;
  fb.height = create.height;
  fb.pixel_format = DRM_FORMAT_XRGB8888;
  fb.handles[0] = create.handle;
  fb.pitches[0] = create.pitch;
  if (card.ioctl(DRM_IOCTL_MODE_ADDFB2, fb, true)) {
    buffer.fb_id_ = fb.fb_id;
  } else {
    // Drivers from before ADDFB2 take the depth/bpp form, which means XRGB8888.
    const int err2 = errno;
    drm_mode_fb_cmd legacy{};
    legacy.width = create.width;
    legacy.height = create.height;
    legacy.pitch = create.pitch;
    legacy.bpp = 32;
    legacy.depth = 24;
    legacy.handle = create.handle;
    if (!card.ioctl(DRM_IOCTL_MODE_ADDFB, legacy, true))
      return fail("DRM_IOCTL_MODE_ADDFB2 XRGB8888: " + errno_text(err2) +
                  "; DRM_IOCTL_MODE_ADDFB: " + errno_text(errno));
    buffer.fb_id_ = legacy.fb_id;
  }

  drm_mode_map_dumb map{};
  map.handle = create.handle;
  if (!card.ioctl(DRM_IOCTL_MODE_MAP_DUMB, map, true))
    return fail("DRM_IOCTL_MODE_MAP_DUMB: " + errno_text(errno));
  void *bytes = ::mmap(nullptr, buffer.size_, PROT_READ | PROT_WRITE, MAP_SHARED, card.fd(),
                       static_cast<off_t>(map.offset));
  if (bytes == MAP_FAILED)
    return fail("mmap of a dumb buffer: " + errno_text(errno));
  buffer.map_ = static_cast<std::uint8_t *>(bytes);
  return buffer;
}

void DumbBuffer::release(const CardFile &card) {
  if (map_ != nullptr)
    ::munmap(std::exchange(map_, nullptr), size_);
  if (fb_id_ != 0) {
    std::uint32_t fb = std::exchange(fb_id_, 0);
    (void)card.ioctl(DRM_IOCTL_MODE_RMFB, fb, true);
  }
  if (handle_ != 0) {
    drm_mode_destroy_dumb destroy{};
    destroy.handle = std::exchange(handle_, 0);
    (void)card.ioctl(DRM_IOCTL_MODE_DESTROY_DUMB, destroy, true);
  }
  size_ = 0;
}

} // namespace camhead::hal::output::drm
