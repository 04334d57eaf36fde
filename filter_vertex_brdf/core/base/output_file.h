#pragma once
// Output files, nothing lost: a file is written to a temporary <path>.tmp<pid> in its own folder,
// flushed to disk and only then renamed over <path>, so <path> always holds either the previous
// complete file or the new complete one (a run killed half-way leaves the previous file and, at
// worst, its temporary, which the next run writing that path removes). An existing file is
// replaced only when the caller's policy allows it, and the caller says so in its log.
#include <string>

namespace vbrdf {

// What may happen to a file already at an output path.
enum class OverwritePolicy { Refuse = 0, Replace = 1 };

// Checks, before any work, that `path` can be written: throws InputError naming the file and
// `parameter` (the dialog label of the output or overwrite setting) when it is a folder, when its
// folder is missing or not writable, or when it exists and `policy` is Refuse. Returns what
// writing will do, for the log: "new file" or "replaces the existing file (N bytes)".
std::string check_output_path(const std::string &path, OverwritePolicy policy, const std::string &parameter);

// Removes the temporaries <name>.tmp<pid> beside `path` whose process no longer runs (left by a
// run that was killed while writing); those of running processes are left alone. Returns how many.
size_t remove_stale_temporaries(const std::string &path);

// One output file being written: temporary() is where to write it; commit() flushes it to disk,
// checks that `expected_bytes` (when > 0) were written and renames it over the final path. A
// temporary that was not committed is removed on destruction. While any AtomicOutput lives,
// SIGXFSZ (file size limit, `ulimit -f`) is ignored so that a write beyond the limit fails with
// an error instead of killing MeshLab. Errors (ProcessingError) name the file and the cause (disk
// full, file size limit, folder not writable) and say that the previous file is unchanged.
class AtomicOutput {
public:
  explicit AtomicOutput(const std::string &path);
  ~AtomicOutput();
  AtomicOutput(const AtomicOutput &) = delete;
  AtomicOutput &operator=(const AtomicOutput &) = delete;
  const std::string &path() const { return path_; }
  const std::string &temporary() const { return tmp_; }
  // Throws ProcessingError (the temporary is removed) when the temporary is missing or short.
  void commit(long long expected_bytes = 0);
  // The cause of a failed write of the temporary, for messages ("the disk is full", ...).
  std::string failure_cause() const;

private:
  std::string path_, tmp_;
  bool committed_ = false;
};

// Exclusive lock on an output folder (flock on the folder itself: no lock file is left behind),
// held while a set of outputs that belong together (the fit's PLY and report) is committed, so
// two runs writing the same outputs at once leave the complete set of one of them.
class OutputFolderLock {
public:
  explicit OutputFolderLock(const std::string &folder);
  ~OutputFolderLock();
  OutputFolderLock(const OutputFolderLock &) = delete;
  OutputFolderLock &operator=(const OutputFolderLock &) = delete;

private:
  int fd_ = -1;
};

// Writes a text file atomically (reports, light files, tables), replacing an existing one.
void write_text_file_atomically(const std::string &path, const std::string &text);
// The same, into out.temporary() only (ProcessingError naming the cause on failure).
void stage_text_file(AtomicOutput &out, const std::string &text);

} // namespace vbrdf
