// EvdevDevice: Linux input devices through libevdev (model in evdev_device.hpp).
#include "vrflow/input/evdev_device.hpp"

#include <fcntl.h>
#include <libevdev/libevdev.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "vrflow/message/eigen.hpp"

namespace vrflow::input {

namespace {

/// The button bit of an EV_KEY code, or -1.
int buttonOf(unsigned code) {
  switch (code) {
    case BTN_LEFT:
    case BTN_0:
    case BTN_TRIGGER:
    case BTN_SOUTH:
      return 0;
    case BTN_RIGHT:
    case BTN_1:
    case BTN_THUMB:
    case BTN_EAST:
      return 1;
    case BTN_MIDDLE:
    case BTN_2:
    case BTN_THUMB2:
    case BTN_NORTH:
      return 2;
    default:
      return -1;
  }
}

}  // namespace

Result<std::unique_ptr<EvdevDevice>> EvdevDevice::open(const std::string& path,
                                                       const DeviceOptions& options) {
  if (!(options.scale > 0) || !std::isfinite(options.scale))
    return makeError("evdev:" + path + ": scale must be a positive number");
  std::unique_ptr<EvdevDevice> device(new EvdevDevice(path, options));
  if (auto status = device->attach(); !status && !(options.hotplug && errno == ENOENT))
    return status.error();
  return device;
}

EvdevDevice::EvdevDevice(std::string path, const DeviceOptions& options)
    : path_(std::move(path)), options_(options) {
  state_.position = options_.origin;
  state_.present = false;
}

EvdevDevice::~EvdevDevice() {
  detach();
}

Status EvdevDevice::attach() {
  fd_ = ::open(path_.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const int error = errno;
    Status status =
        makeError("evdev:" + path_ + ": cannot open the input device node (" +
                  std::strerror(error) + (error == ENOENT ? "; set hotplug to wait for it)" : ")"));
    errno = error;
    return status;
  }
  if (const int rc = libevdev_new_from_fd(fd_, &device_); rc < 0) {
    ::close(fd_);
    fd_ = -1;
    device_ = nullptr;
    errno = -rc;
    return makeError("evdev:" + path_ + ": not an input device (" + std::strerror(-rc) + ")");
  }
  name_ = libevdev_get_name(device_) ? libevdev_get_name(device_) : "";
  state_.present = true;
  return {};
}

void EvdevDevice::detach() {
  if (device_) libevdev_free(device_);
  if (fd_ >= 0) ::close(fd_);
  device_ = nullptr;
  fd_ = -1;
  state_.present = false;
}

void EvdevDevice::apply(unsigned type, unsigned code, int value) {
  if (type == EV_KEY) {
    if (const int bit = buttonOf(code); bit >= 0) {
      if (value)
        state_.buttons |= 1u << bit;
      else
        state_.buttons &= ~(1u << bit);
    }
  } else if (type == EV_REL && code <= REL_Z) {
    state_.position[code - REL_X] += options_.scale * value;
  } else if (type == EV_REL && code >= REL_RX && code <= REL_RZ) {
    Eigen::Vector3d axis = Eigen::Vector3d::Zero();
    axis[code - REL_RX] = 1.0;
    auto q = msg::asEigen(state_.orientation);
    q = (Eigen::Quaterniond(Eigen::AngleAxisd(options_.scale * value, axis)) * q).normalized();
  } else if (type == EV_ABS && code <= ABS_Z) {
    const input_absinfo* info = libevdev_get_abs_info(device_, code);
    if (!info || info->maximum <= info->minimum) return;
    const double mid = 0.5 * (info->maximum + info->minimum);
    const double half = 0.5 * (info->maximum - info->minimum);
    state_.position[code - ABS_X] =
        options_.origin[code - ABS_X] + options_.scale * (value - mid) / half;
  }
}

Result<DeviceSample> EvdevDevice::sample(double time) {
  if (!device_) {
    if (auto status = attach(); !status) {
      if (errno != ENOENT) return status.error();
      return state_;  // still missing: waited for
    }
    std::fprintf(stderr, "evdev:%s: picked up '%s'\n", path_.c_str(), name_.c_str());
  }
  input_event event{};
  unsigned flags = LIBEVDEV_READ_FLAG_NORMAL;
  for (;;) {
    const int rc = libevdev_next_event(device_, flags, &event);
    if (rc == LIBEVDEV_READ_STATUS_SYNC) {
      flags = LIBEVDEV_READ_FLAG_SYNC;  // replay the state we missed after a dropped buffer
      apply(event.type, event.code, event.value);
      continue;
    }
    if (rc == LIBEVDEV_READ_STATUS_SUCCESS) {
      apply(event.type, event.code, event.value);
      continue;
    }
    if (rc == -EAGAIN && flags == LIBEVDEV_READ_FLAG_SYNC) {
      flags = LIBEVDEV_READ_FLAG_NORMAL;
      continue;
    }
    if (rc == -EAGAIN) break;
    // -ENODEV (unplugged) or another read error: the device is gone.
    std::fprintf(stderr, "evdev:%s: '%s' went away (%s)%s\n", path_.c_str(), name_.c_str(),
                 std::strerror(-rc), options_.stopOnUnplug ? "" : "; waiting for it to come back");
    detach();
    if (options_.stopOnUnplug) return makeError("evdev:" + path_ + ": the device went away");
    break;
  }
  const double dt = time - lastTime_;
  for (int k = 0; k < 3; ++k) {
    state_.velocity[k] = dt > 0 ? (state_.position[k] - lastPosition_[k]) / dt : 0.0;
    lastPosition_[k] = state_.position[k];
  }
  lastTime_ = time;
  return state_;
}

}  // namespace vrflow::input
