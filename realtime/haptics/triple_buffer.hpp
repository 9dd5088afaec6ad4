#pragma once
// A wait-free single-writer single-reader channel for the newest value (triple buffering): the
// writer fills its private slot and swaps it with the shared one; the reader swaps the shared
// slot in when it is newer. Neither side ever waits or allocates; the reader always sees a
// complete value, the newest one published.

#include <array>
#include <atomic>
#include <cstdint>

namespace kerf {

template <typename T>
class TripleBuffer {
public:
  /// Writer: the slot to fill before publish().
  T& write_slot() noexcept { return m_slots[m_write]; }
  /// Writer: makes the filled slot the newest value.
  void publish() noexcept {
    const std::uint8_t previous = m_shared.exchange(static_cast<std::uint8_t>(m_write | fresh), std::memory_order_acq_rel);
    m_write = previous & index;
  }
  /// Reader: takes the newest value if one was published since the last call; returns whether
  /// it did. read_slot() is the newest value taken.
  bool update() noexcept {
    if (!(m_shared.load(std::memory_order_relaxed) & fresh)) return false;
    const std::uint8_t previous = m_shared.exchange(m_read, std::memory_order_acq_rel);
    m_read = previous & index;
    return true;
  }
  [[nodiscard]] const T& read_slot() const noexcept { return m_slots[m_read]; }

private:
  static constexpr std::uint8_t index = 0x3, fresh = 0x4;
  std::array<T, 3> m_slots{};
  std::uint8_t m_write = 0;
  std::uint8_t m_read = 1;
  std::atomic<std::uint8_t> m_shared{2};
};

} // namespace kerf
