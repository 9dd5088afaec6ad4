#pragma once
// Records every servo tick to a session file (session_file.hpp) without touching the disk from
// the servo thread: the servo pushes TickRecords into a single-producer single-consumer ring
// allocated once; a writer thread drains it every 20 ms, formats the rows and appends them with
// one flush per batch. A full ring drops the record and counts it (the servo never waits).

#include "realtime/haptics/session_file.hpp"

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <thread>
#include <vector>

namespace kerf {

class SessionRecorder {
public:
  /// Creates (truncates) `file`, writes the header and starts the writer thread. `capacity` is
  /// the ring size in ticks (at least 2 s of ticks is advised). Throws std::runtime_error naming
  /// the file when it cannot be opened, std::invalid_argument on a header with no tools or more
  /// than max_session_tools.
  SessionRecorder(const std::filesystem::path& file, const SessionHeader& header, std::size_t capacity);
  ~SessionRecorder();
  SessionRecorder(const SessionRecorder&) = delete;
  SessionRecorder& operator=(const SessionRecorder&) = delete;

  /// Servo side: copies the record into the ring. Allocation-free, lock-free, wait-free.
  /// Returns false (and counts it) when the ring is full.
  bool push(const TickRecord& record) noexcept;
  /// Writes everything still in the ring, flushes, fsyncs and closes the file. Idempotent.
  void close();

  [[nodiscard]] std::uint64_t written() const noexcept { return m_written.load(); }
  [[nodiscard]] std::uint64_t dropped() const noexcept { return m_dropped.load(); }
  [[nodiscard]] const std::filesystem::path& file() const noexcept { return m_path; }

private:
  void drain();
  void writer_loop();

  std::filesystem::path m_path;
  SessionHeader m_header;
  std::FILE* m_file = nullptr;
  std::vector<TickRecord> m_ring;
  std::atomic<std::uint64_t> m_head{0}; // next slot the servo writes
  std::atomic<std::uint64_t> m_tail{0}; // next slot the writer reads
  std::atomic<std::uint64_t> m_written{0};
  std::atomic<std::uint64_t> m_dropped{0};
  std::atomic<bool> m_stop{false};
  std::thread m_writer;
};

} // namespace kerf
