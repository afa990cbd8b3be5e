#pragma once
/// \file
/// Private to core/: paths a signal handler may read, for the files and folders a run must remove
/// when it is interrupted (atomic_file.cpp's temporaries, staged_folder.cpp's staging folders).
///
/// Fixed slots of plain characters, each guarded by a lock-free atomic state, so the handler reads
/// them without locks or allocation. A registration that finds every slot taken still works; its
/// path is just not removed on a signal (the next run's stale sweep removes it).
///   kFree -> kFilling (a writer claims the slot and copies its path) -> kLive
///   kLive -> kRemoving (the handler acts on it) -> kLive
///   kLive -> kFree (the writer is done with it; waits while the handler acts on it)

#include <sched.h>

#include <array>
#include <atomic>
#include <cstddef>
#include <cstring>
#include <string>

namespace elastic::core_detail {

template <int Slots>
class SignalPathRegistry {
 public:
  /// A slot for `path`, or -1 when none is free or the path is too long.
  int add(const std::string& path) noexcept {
    if (path.size() + 1 > kPathBytes) {
      return -1;
    }
    for (int i = 0; i < Slots; ++i) {
      Slot& slot = slots_[static_cast<size_t>(i)];
      int expected = kFree;
      if (slot.state.compare_exchange_strong(expected, kFilling, std::memory_order_acquire)) {
        std::memcpy(slot.path, path.c_str(), path.size() + 1);
        slot.state.store(kLive, std::memory_order_release);
        return i;
      }
    }
    return -1;
  }

  void release(int i) noexcept {
    if (i < 0) {
      return;
    }
    Slot& slot = slots_[static_cast<size_t>(i)];
    int expected = kLive;
    // While a handler acts on this path (kRemoving), wait: its bytes must not change under it.
    while (!slot.state.compare_exchange_weak(expected, kFree, std::memory_order_acq_rel)) {
      expected = kLive;
      sched_yield();
    }
  }

  /// Calls f(path) on every live path (from a signal handler: f must be async-signal-safe).
  template <class F>
  void for_each_live(F&& f) noexcept {
    for (Slot& slot : slots_) {
      int expected = kLive;
      if (slot.state.compare_exchange_strong(expected, kRemoving, std::memory_order_acquire)) {
        f(static_cast<const char*>(slot.path));
        slot.state.store(kLive, std::memory_order_release);
      }
    }
  }

 private:
  static constexpr size_t kPathBytes = 4096;
  enum : int { kFree, kFilling, kLive, kRemoving };
  struct Slot {
    std::atomic<int> state{kFree};
    char path[kPathBytes] = {};
  };
  static_assert(std::atomic<int>::is_always_lock_free,
                "the signal handler needs lock-free atomics");
  std::array<Slot, Slots> slots_;
};

}  // namespace elastic::core_detail
