#pragma once
// An X display for the viewer's tests: the one in DISPLAY if it can be opened, else a private
// Xvfb server started for the test program (Xvfb picks a free display number and reports it on a
// pipe, -displayfd) and stopped at its end. Registered as a GoogleTest global environment by
// linking xvfb_display.cpp; a program that cannot get a display fails with the reason.

#include <string>

namespace kerf::test {

/// The display the tests render on (":N"), set once the environment is up.
const std::string& test_display();

} // namespace kerf::test
