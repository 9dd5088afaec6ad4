#include "experiments/study/study_progress.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace kerf {

StudyProgress::StudyProgress(std::string study, std::FILE* out)
    : m_study(std::move(study)), m_out(out), m_begin(std::chrono::steady_clock::now()) {}

std::string human_duration(double seconds) {
  char text[64];
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) return "?";
  if (seconds < 10.0) {
    std::snprintf(text, sizeof text, "%.2g s", seconds);
  } else if (seconds < 60.0) {
    std::snprintf(text, sizeof text, "%.0f s", seconds);
  } else if (seconds < 3600.0) {
    const long s = std::lround(seconds);
    std::snprintf(text, sizeof text, "%ld min %ld s", s / 60, s % 60);
  } else {
    const long m = std::lround(seconds / 60.0);
    std::snprintf(text, sizeof text, "%ld h %ld min", m / 60, m % 60);
  }
  return text;
}

void StudyProgress::expect(Kind kind, std::size_t pieces) {
  const std::lock_guard lock(m_mutex);
  m_counts[static_cast<int>(kind)].expected += pieces;
}

void StudyProgress::finished(Kind kind, const std::string& what, double seconds) {
  const std::lock_guard lock(m_mutex);
  Count& c = m_counts[static_cast<int>(kind)];
  ++c.done;
  c.expected = std::max(c.expected, c.done);
  c.seconds += seconds;
  if (!m_out) return;
  // Time left: per kind, the mean of its finished pieces times the pieces left.
  std::size_t done = 0, total = 0;
  double left = 0.0;
  bool unknown = false;
  for (const Count& k : m_counts) {
    done += k.done;
    total += k.expected;
    if (k.expected == k.done) continue;
    if (k.done == 0) unknown = true;
    else left += k.seconds / static_cast<double>(k.done) * static_cast<double>(k.expected - k.done);
  }
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_begin).count();
  std::fprintf(m_out, "study %s: %zu/%zu %s in %s; elapsed %s, ETA %s%s\n", m_study.c_str(), done, total, what.c_str(),
               human_duration(seconds).c_str(), human_duration(elapsed).c_str(), unknown ? ">= " : "~", human_duration(left).c_str());
  std::fflush(m_out);
}

std::size_t StudyProgress::done() const {
  const std::lock_guard lock(m_mutex);
  std::size_t n = 0;
  for (const Count& k : m_counts) n += k.done;
  return n;
}

} // namespace kerf
