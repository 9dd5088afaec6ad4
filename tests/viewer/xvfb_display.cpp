#include "tests/viewer/xvfb_display.hpp"

#include <gtest/gtest.h>

#include <X11/Xlib.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

namespace kerf::test {

namespace {

std::string display_name;

bool can_open(const char* name) {
  if (!name || !*name) return false;
  Display* d = XOpenDisplay(name);
  if (!d) return false;
  XCloseDisplay(d);
  return true;
}

class XvfbEnvironment : public ::testing::Environment {
public:
  void SetUp() override {
    if (can_open(std::getenv("DISPLAY"))) {
      display_name = std::getenv("DISPLAY");
      return;
    }
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0) << std::strerror(errno);
    m_pid = ::fork();
    ASSERT_GE(m_pid, 0) << std::strerror(errno);
    if (m_pid == 0) {
      // Child: the pipe's write end becomes fd 3 for -displayfd; Xvfb's chatter goes to /dev/null.
      // -noreset: an X server resets when its last client disconnects, and a kerf process that
      // connects during the reset fails ("bad X server connection"); the tests run one kerf
      // process after another, so the server must stay up between them.
      ::dup2(fds[1], 3);
      const int null = ::open("/dev/null", O_WRONLY);
      ::dup2(null, 1);
      ::dup2(null, 2);
      ::execlp("Xvfb", "Xvfb", "-displayfd", "3", "-screen", "0", "1600x1200x24", "-nolisten", "tcp", "-noreset",
               static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(fds[1]);
    std::string number;
    pollfd p{fds[0], POLLIN, 0};
    char c = 0;
    while (::poll(&p, 1, 30000) > 0 && ::read(fds[0], &c, 1) == 1 && c != '\n') number += c;
    ::close(fds[0]);
    ASSERT_FALSE(number.empty()) << "could not start Xvfb (is the xvfb package installed? "
                                    "experiments/setup_and_run.sh installs it); the viewer's tests need an X display";
    display_name = ":" + number;
    ::setenv("DISPLAY", display_name.c_str(), 1);
    ASSERT_TRUE(can_open(display_name.c_str())) << "Xvfb started on " << display_name << " but cannot be opened";
  }
  void TearDown() override {
    if (m_pid > 0) {
      ::kill(m_pid, SIGTERM);
      ::waitpid(m_pid, nullptr, 0);
      m_pid = -1;
    }
  }

private:
  pid_t m_pid = -1;
};

[[maybe_unused]] const ::testing::Environment* const environment = ::testing::AddGlobalTestEnvironment(new XvfbEnvironment);

} // namespace

const std::string& test_display() { return display_name; }

} // namespace kerf::test
