// See shared_manager.h.
#include "shared_manager.h"

#include <condition_variable>
#include <mutex>
#include <system_error>

namespace camhead::hal::camera {
namespace {

// Whether a manager exists, counting one whose last holder is deleting it:
// a new one must wait for that, or libcamera aborts on two at once.
struct Registry {
  std::mutex mutex;
  std::condition_variable gone;
  std::weak_ptr<libcamera::CameraManager> current;
  bool alive = false;
};

Registry &registry() {
  // Never destroyed: a manager's deleter may run during exit.
  static auto *const instance = new Registry;
  return *instance;
}

} // namespace

std::shared_ptr<libcamera::CameraManager> shared_camera_manager(std::string &error) {
  Registry &r = registry();
  std::unique_lock lock(r.mutex);
  if (std::shared_ptr<libcamera::CameraManager> manager = r.current.lock())
    return manager;
  r.gone.wait(lock, [&] { return !r.alive; });
  auto manager = std::make_unique<libcamera::CameraManager>();
  if (const int ret = manager->start(); ret < 0) {
    error = "libcamera: CameraManager::start: " +
            std::error_code(-ret, std::generic_category()).message();
    return nullptr;
  }
  std::shared_ptr<libcamera::CameraManager> shared(manager.release(),
                                                   [](libcamera::CameraManager *gone) {
                                                     delete gone; // stops it
                                                     Registry &reg = registry();
                                                     const std::lock_guard done(reg.mutex);
                                                     reg.alive = false;
                                                     reg.gone.notify_all();
                                                   });
  r.alive = true;
  r.current = shared;
  return shared;
}

} // namespace camhead::hal::camera
