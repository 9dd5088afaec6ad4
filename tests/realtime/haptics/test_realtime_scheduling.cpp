// CPU placement of the servo thread (realtime/haptics/realtime_scheduling.hpp): the live view
// pins the servo to a CPU of its own and keeps the render thread off it. Checked against the
// kernel's own record of each thread's mask (pthread_getaffinity_np, sched_getcpu).

#include "realtime/haptics/realtime_scheduling.hpp"

#include <gtest/gtest.h>

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <thread>

using namespace kerf;

namespace {

cpu_set_t own_mask() {
  cpu_set_t set;
  CPU_ZERO(&set);
  EXPECT_EQ(pthread_getaffinity_np(pthread_self(), sizeof set, &set), 0);
  return set;
}

} // namespace

TEST(RealtimeScheduling, TheLastOfSeveralCpusIsInTheMaskAndNoneHigherIs) {
  const cpu_set_t set = own_mask();
  const int cpu = last_of_several_cpus();
  if (CPU_COUNT(&set) < 2) {
    EXPECT_EQ(cpu, -1); // one CPU: nothing to give a thread of its own
    return;
  }
  ASSERT_GE(cpu, 0);
  EXPECT_TRUE(CPU_ISSET(cpu, &set));
  for (int c = cpu + 1; c < CPU_SETSIZE; ++c) EXPECT_FALSE(CPU_ISSET(c, &set)) << c;
}

TEST(RealtimeScheduling, KeepingOffACpuRemovesItFromThisThreadAndItsNewThreadsUntilRestored) {
  const cpu_set_t before = own_mask();
  const int cpu = last_of_several_cpus();
  if (cpu < 0) GTEST_SKIP() << "one CPU: keep_off_cpu leaves the thread where it is";
  const CpuMask saved = keep_off_cpu(cpu);
  ASSERT_TRUE(saved.saved);
  const cpu_set_t during = own_mask();
  EXPECT_FALSE(CPU_ISSET(cpu, &during));
  EXPECT_EQ(CPU_COUNT(&during), CPU_COUNT(&before) - 1);
  // A thread started now inherits the mask (the GL driver's threads, the model thread).
  cpu_set_t child;
  std::thread([&] { child = own_mask(); }).join();
  EXPECT_TRUE(CPU_EQUAL(&child, &during));
  // Nothing to keep off twice: the CPU is no longer in the mask, the mask is not saved again.
  EXPECT_FALSE(keep_off_cpu(cpu).saved);
  restore_cpus(saved);
  const cpu_set_t after = own_mask();
  EXPECT_TRUE(CPU_EQUAL(&after, &before));
}

TEST(RealtimeScheduling, APinnedThreadRunsOnItsCpuAlone) {
  const int cpu = last_of_several_cpus();
  if (cpu < 0) GTEST_SKIP() << "one CPU";
  std::thread([cpu] {
    ASSERT_TRUE(pin_to_cpu(cpu));
    const cpu_set_t set = own_mask();
    EXPECT_EQ(CPU_COUNT(&set), 1);
    EXPECT_TRUE(CPU_ISSET(cpu, &set));
    EXPECT_EQ(sched_getcpu(), cpu); // the kernel moved it there before returning
  }).join();
  EXPECT_FALSE(pin_to_cpu(-1));
  EXPECT_FALSE(pin_to_cpu(CPU_SETSIZE));
}

TEST(RealtimeScheduling, EnteringRealtimeOnACpuReportsThePinAndNeverThrows) {
  const int cpu = last_of_several_cpus();
  if (cpu < 0) GTEST_SKIP() << "one CPU";
  std::thread([cpu] {
    const RealtimeSetup setup = enter_realtime(1, cpu); // SCHED_FIFO and the lock may be refused: warnings say so
    EXPECT_EQ(setup.cpu, cpu);
    const cpu_set_t set = own_mask();
    EXPECT_EQ(CPU_COUNT(&set), 1);
    if (setup.locked) munlockall(); // the lock is the process's: the other tests run unlocked
  }).join();
}
