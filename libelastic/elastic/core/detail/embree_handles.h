#pragma once
/// \file
/// RAII handles of Embree 3 for the library's two users of it, the closest-point projector
/// (projection/) and the ray tracer (render/). Private: not installed (Embree is a private
/// dependency of libelastic), included only from .cpp files.
///
/// Errors are `Error`s naming the input the device or scene is for (a surface name, "render") and
/// Embree's error code.

#include <embree3/rtcore.h>

#include <memory>
#include <mutex>
#include <string>

#include "elastic/core/error.h"

namespace elastic::detail {

/// Throws Error naming `input` when Embree reports an error on `device` (e.g. after committing a
/// scene): "Embree failed to <what> (error N)".
inline void check_embree(RTCDevice device, const std::string& input, const std::string& what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE) {
    throw Error(input, "Embree failed to " + what + " (error " +
                           std::to_string(static_cast<int>(error)) + ")");
  }
}

/// An Embree device: created on construction, released on destruction; not copyable.
class EmbreeDevice {
 public:
  /// \throws Error naming `input` when Embree cannot create a device.
  explicit EmbreeDevice(const std::string& input) : handle_(rtcNewDevice(nullptr)) {
    if (!handle_) {
      throw Error(input, "cannot create an Embree device (error " +
                             std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
    }
  }
  ~EmbreeDevice() { rtcReleaseDevice(handle_); }
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;

  RTCDevice get() const { return handle_; }

 private:
  RTCDevice handle_;
};

/// One device for the whole process, shared by its holders: created by the first call while no
/// holder is alive, released with the last holder (a device costs threads and memory, and Embree
/// devices may be shared by any number of scenes and threads).
/// \throws Error naming `input` when Embree cannot create the device.
inline std::shared_ptr<EmbreeDevice> shared_embree_device(const std::string& input) {
  static std::mutex mutex;
  static std::weak_ptr<EmbreeDevice> weak;
  const std::lock_guard<std::mutex> lock(mutex);
  std::shared_ptr<EmbreeDevice> device = weak.lock();
  if (!device) {
    device = std::make_shared<EmbreeDevice>(input);
    weak = device;
  }
  return device;
}

/// An Embree scene on a device (which must outlive it): released on destruction; not copyable.
class EmbreeScene {
 public:
  /// \throws Error naming `input` when Embree cannot create the scene.
  EmbreeScene(RTCDevice device, const std::string& input) : handle_(rtcNewScene(device)) {
    if (!handle_) {
      throw Error(input, "cannot create the Embree scene");
    }
  }
  ~EmbreeScene() { rtcReleaseScene(handle_); }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  RTCScene get() const { return handle_; }

 private:
  RTCScene handle_;
};

}  // namespace elastic::detail
