// A Linux input device made with uinput moves the pointer; it going away and coming back is
// hot-plug. Skipped, with the reason, where /dev/uinput cannot be opened (containers, CI
// without the uinput kernel module).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <libevdev/libevdev-uinput.h>
#include <libevdev/libevdev.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "vrflow/input/evdev_device.hpp"

namespace vrflow::input {
namespace {

/// A virtual 3-axis relative device with a left button, made through /dev/uinput.
class VirtualDevice {
 public:
  VirtualDevice() {
    const int fd = ::open("/dev/uinput", O_RDWR | O_CLOEXEC);
    if (fd < 0) {
      why_ = std::string("/dev/uinput: ") + std::strerror(errno);
      return;
    }
    ::close(fd);
    libevdev* prototype = libevdev_new();
    libevdev_set_name(prototype, "vrflow test spacemouse");
    libevdev_enable_event_type(prototype, EV_REL);
    for (const unsigned code : {REL_X, REL_Y, REL_Z})
      libevdev_enable_event_code(prototype, EV_REL, code, nullptr);
    libevdev_enable_event_type(prototype, EV_KEY);
    libevdev_enable_event_code(prototype, EV_KEY, BTN_LEFT, nullptr);
    const int rc =
        libevdev_uinput_create_from_device(prototype, LIBEVDEV_UINPUT_OPEN_MANAGED, &uinput_);
    libevdev_free(prototype);
    if (rc < 0) why_ = std::string("uinput device: ") + std::strerror(-rc);
  }
  ~VirtualDevice() { destroy(); }
  VirtualDevice(const VirtualDevice&) = delete;
  VirtualDevice& operator=(const VirtualDevice&) = delete;
  bool ok() const { return uinput_ != nullptr; }
  const std::string& why() const { return why_; }
  std::string node() const { return libevdev_uinput_get_devnode(uinput_); }
  void send(unsigned type, unsigned code, int value) {
    libevdev_uinput_write_event(uinput_, type, code, value);
  }
  void sync() { send(EV_SYN, SYN_REPORT, 0); }
  void destroy() {
    if (uinput_) libevdev_uinput_destroy(uinput_);
    uinput_ = nullptr;
  }

 private:
  libevdev_uinput* uinput_ = nullptr;
  std::string why_;
};

TEST(EvdevDevice, UinputDeviceMovesThePointerAndHotplugSeesItGo) {
  VirtualDevice virtualDevice;
  if (!virtualDevice.ok()) GTEST_SKIP() << "no uinput here (" << virtualDevice.why() << ")";
  usleep(200000);  // udev makes the node
  DeviceOptions options;
  options.scale = 0.001;
  auto device = EvdevDevice::open(virtualDevice.node(), options);
  ASSERT_TRUE(device) << device.error().message;
  EXPECT_EQ((*device)->name(), "vrflow test spacemouse");
  virtualDevice.send(EV_REL, REL_X, 100);
  virtualDevice.send(EV_REL, REL_Y, -50);
  virtualDevice.send(EV_KEY, BTN_LEFT, 1);
  virtualDevice.sync();
  usleep(50000);
  auto moved = (*device)->sample(0.1);
  ASSERT_TRUE(moved);
  EXPECT_TRUE(moved->present);
  EXPECT_NEAR(moved->position[0], 0.1, 1e-12);
  EXPECT_NEAR(moved->position[1], -0.05, 1e-12);
  EXPECT_EQ(moved->buttons, 1u);
  virtualDevice.destroy();
  usleep(200000);
  auto gone = (*device)->sample(0.2);
  ASSERT_TRUE(gone);  // on-unplug keep: the module goes on
  EXPECT_FALSE(gone->present);
}

}  // namespace
}  // namespace vrflow::input
