#pragma once
// The two callbacks every long-running stage takes: a log line sink and a progress report.
#include <functional>
#include <string>

namespace vbrdf {

// One human-readable line (no trailing newline), for MeshLab's log or a tool's stderr.
using LogFn = std::function<void(const std::string &line)>;

// Progress: fraction in [0,1] and a short label. Returns false to cancel (core then throws
// ProcessingError("cancelled")).
using ProgressFn = std::function<bool(float fraction, const char *stage)>;

} // namespace vbrdf
