#pragma once
// The machine a study's costs were measured on, for the table's caption: the CPU model and the
// number of cores (a cost means nothing without the machine it was measured on).

#include <string>

namespace kerf {

/// The CPU model in the text of /proc/cpuinfo: the first "model name" line's value, trimmed (x86),
/// else the first "Hardware" or "Processor" line's (older ARM kernels); "" when there is none.
std::string cpu_model_name(const std::string& cpuinfo);

/// "<CPU model>, <n> cores" for this machine (/proc/cpuinfo, std::thread::hardware_concurrency);
/// "unknown CPU" when /proc/cpuinfo names none.
std::string machine_label();

} // namespace kerf
