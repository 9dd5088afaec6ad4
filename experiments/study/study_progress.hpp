#pragma once
// A study's progress line (docs/studies.md): one line on stderr per finished run — the reference
// solves, the model runs, the fits, the timed runs — saying what finished, how many of how many,
// the time so far and an estimate of the time left: for each kind of piece, the mean time of its
// finished pieces times those left, summed (a lower bound, "≥", while a kind has none finished;
// rough: pieces of one kind differ, and some run beside others).

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <mutex>
#include <string>

namespace kerf {

class StudyProgress {
public:
  /// The kinds of piece, each with its own mean time.
  enum class Kind { reference_solve, model_run, fit, timing };

  /// `study` names the study in each line; lines go to `out` (nullptr: silent).
  explicit StudyProgress(std::string study, std::FILE* out = stderr);

  /// `pieces` more pieces of `kind` are expected.
  void expect(Kind kind, std::size_t pieces);
  /// One piece of `kind` finished: "study NAME: 7/41 potato_rect_cut · fracture: ran in 0.41 s;
  /// elapsed 12 s, ETA ~1 min 10 s". `what` says which piece and how it ended. Thread-safe.
  void finished(Kind kind, const std::string& what, double seconds);

  [[nodiscard]] std::size_t done() const;

private:
  struct Count {
    std::size_t expected = 0, done = 0;
    double seconds = 0.0;
  };
  mutable std::mutex m_mutex;
  std::string m_study;
  Count m_counts[4];
  std::FILE* m_out;
  std::chrono::steady_clock::time_point m_begin;
};

/// "45 s", "2 min 10 s", "1 h 3 min": a duration for a person.
std::string human_duration(double seconds);

} // namespace kerf
