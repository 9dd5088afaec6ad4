#include "realtime/haptics/session_recorder.hpp"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <unistd.h>

namespace kerf {

SessionRecorder::SessionRecorder(const std::filesystem::path& file, const SessionHeader& header, std::size_t capacity)
    : m_path(file), m_header(header), m_ring(std::max<std::size_t>(capacity, 2)) {
  if (header.tools.empty() || header.tools.size() > static_cast<std::size_t>(max_session_tools))
    throw std::invalid_argument("session recorder: a session has 1 to " + std::to_string(max_session_tools) +
                                " tools, got " + std::to_string(header.tools.size()));
  m_file = std::fopen(file.c_str(), "w");
  if (!m_file) throw std::runtime_error(file.string() + ": cannot open the session file: " + std::strerror(errno));
  std::string tools;
  for (const std::string& t : header.tools) tools += (tools.empty() ? "" : ";") + t;
  std::fprintf(m_file, "# kerf haptic session v1\n# rate_hz=%.17g model=%s scene=%s tools=%s\n%s\n", header.rate,
               header.model.c_str(), header.scene.c_str(), tools.c_str(), session_csv_header);
  std::fflush(m_file);
  m_writer = std::thread([this] { writer_loop(); });
}

SessionRecorder::~SessionRecorder() {
  try {
    close();
  } catch (...) { // a destructor must not throw; close() reports errors when called explicitly
  }
}

bool SessionRecorder::push(const TickRecord& record) noexcept {
  const std::uint64_t head = m_head.load(std::memory_order_relaxed);
  if (head - m_tail.load(std::memory_order_acquire) >= m_ring.size()) {
    m_dropped.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  m_ring[head % m_ring.size()] = record;
  m_head.store(head + 1, std::memory_order_release);
  return true;
}

void SessionRecorder::drain() {
  const std::uint64_t head = m_head.load(std::memory_order_acquire);
  std::uint64_t tail = m_tail.load(std::memory_order_relaxed);
  for (; tail != head; ++tail) {
    const TickRecord& r = m_ring[tail % m_ring.size()];
    // One row per tool of the header (a record carries max_session_tools slots).
    for (std::size_t i = 0; i < m_header.tools.size(); ++i) {
      const ToolTick& k = r.tool[i];
      const std::string& name = m_header.tools[i];
      std::fprintf(m_file,
                   "%llu,%.17g,%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%u,%.17g,%.17g,%.17g,"
                   "%.17g,%.17g,%.17g,%s,%.17g,%.9g,%.9g,%.9g,%u,%.17g\n",
                   static_cast<unsigned long long>(r.tick), r.t, name.c_str(), k.position.x(), k.position.y(),
                   k.position.z(), k.velocity.x(), k.velocity.y(), k.velocity.z(), k.orientation[0],
                   k.orientation[1], k.orientation[2], k.orientation[3], k.buttons, k.model_force.x(),
                   k.model_force.y(), k.model_force.z(), k.force.x(), k.force.y(), k.force.z(),
                   std::string(to_string(k.mode)).c_str(), k.crack_extent, r.compute, r.late, k.link_age, k.status,
                   k.injected);
    }
    m_tail.store(tail + 1, std::memory_order_release);
    m_written.fetch_add(1, std::memory_order_relaxed);
  }
  std::fflush(m_file);
}

void SessionRecorder::writer_loop() {
  while (!m_stop.load(std::memory_order_acquire)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    drain();
  }
}

void SessionRecorder::close() {
  if (!m_file) return;
  m_stop.store(true, std::memory_order_release);
  if (m_writer.joinable()) m_writer.join();
  drain();
  const bool ok = std::fflush(m_file) == 0 && fsync(fileno(m_file)) == 0;
  const bool closed = std::fclose(m_file) == 0;
  m_file = nullptr;
  if (!ok || !closed) throw std::runtime_error(m_path.string() + ": writing the session file failed");
}

} // namespace kerf
