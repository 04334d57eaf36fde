#include "base/output_file.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "base/errors.h"
#include "base/file_util.h"

namespace vbrdf {

namespace {

bool is_folder(const std::string &path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

long long file_size(const std::string &path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 ? (long long)st.st_size : -1;
}

// SIGXFSZ ignored while any AtomicOutput lives (a filter runs in one thread; counted anyway).
std::atomic<int> g_guards{0};
struct sigaction g_previous;

void ignore_file_size_signal() {
  if (g_guards++ > 0) return;
  struct sigaction ignore;
  std::memset(&ignore, 0, sizeof ignore);
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  ::sigaction(SIGXFSZ, &ignore, &g_previous);
}

void restore_file_size_signal() {
  if (--g_guards == 0) ::sigaction(SIGXFSZ, &g_previous, nullptr);
}

void sync_file(const std::string &path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

} // namespace

std::string check_output_path(const std::string &path, OverwritePolicy policy, const std::string &parameter) {
  const std::string folder = directory_of(path);
  if (is_folder(path))
    throw InputError("The output '" + path + "' is a folder: give a file name in '" + parameter + "'.");
  if (!is_folder(folder))
    throw InputError("The output folder '" + folder + "' of '" + path + "' does not exist: create it or choose "
                     "another file in '" + parameter + "'.");
  if (::access(folder.c_str(), W_OK) != 0)
    throw InputError("The output folder '" + folder + "' is not writable (" + std::strerror(errno) +
                     "): choose another folder in '" + parameter + "' or make it writable. Nothing was written.");
  const long long size = file_size(path);
  if (size < 0) return "new file";
  if (policy == OverwritePolicy::Refuse)
    throw InputError("The output '" + path + "' already exists and 'Overwrite existing output' is off: move it "
                     "away, choose another file in '" + parameter + "', or turn 'Overwrite existing output' on. "
                     "Nothing was written.");
  return "replaces the existing file (" + std::to_string(size) + " bytes)";
}

size_t remove_stale_temporaries(const std::string &path) {
  const std::string folder = directory_of(path), prefix = file_name_of(path) + ".tmp";
  DIR *dir = ::opendir(folder.c_str());
  if (!dir) return 0;
  size_t removed = 0;
  while (const dirent *e = ::readdir(dir)) {
    const std::string name = e->d_name;
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9) continue;
    const pid_t pid = pid_t(std::stol(digits));
    if (pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;  // running (or not ours to judge)
    if (std::remove(join_path(folder, name).c_str()) == 0) ++removed;
  }
  ::closedir(dir);
  return removed;
}

AtomicOutput::AtomicOutput(const std::string &path) : path_(path), tmp_(path + ".tmp" + std::to_string(::getpid())) {
  remove_stale_temporaries(path_);
  ignore_file_size_signal();
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) std::remove(tmp_.c_str());
  restore_file_size_signal();
}

std::string AtomicOutput::failure_cause() const {
  const std::string folder = directory_of(path_);
  struct rlimit limit;
  const long long written = std::max(0LL, file_size(tmp_));
  if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
      (long long)limit.rlim_cur <= written + 4096)
    return "the file size limit of this process (ulimit -f: " + std::to_string((long long)limit.rlim_cur) +
           " bytes) was reached";
  struct statvfs fs;
  if (::statvfs(folder.c_str(), &fs) == 0 && (unsigned long long)fs.f_bavail * fs.f_frsize < (1ull << 20))
    return "the disk holding '" + folder + "' is full";
  if (::access(folder.c_str(), W_OK) != 0) return "the folder '" + folder + "' is not writable";
  return "the file could not be written completely (" + std::to_string(written) + " bytes written)";
}

void AtomicOutput::commit(long long expected_bytes) {
  const long long size = file_size(tmp_);
  if (size < 0 || (expected_bytes > 0 && size != expected_bytes)) {
    const std::string cause = failure_cause();
    std::remove(tmp_.c_str());
    throw ProcessingError("Cannot write '" + path_ + "': " + cause + ". Free space or choose another folder; " +
                          (file_exists(path_) ? "the previous file is unchanged." : "nothing was written."));
  }
  sync_file(tmp_);
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    std::remove(tmp_.c_str());
    throw ProcessingError("Cannot move the result into place at '" + path_ + "' (" + why +
                          "): check that the folder is writable.");
  }
  committed_ = true;
  sync_file(directory_of(path_));  // the rename itself reaches the disk
}

OutputFolderLock::OutputFolderLock(const std::string &folder) {
  fd_ = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd_ >= 0) ::flock(fd_, LOCK_EX);  // no lock (odd file system): renames stay atomic per file
}

OutputFolderLock::~OutputFolderLock() {
  if (fd_ >= 0) {
    ::flock(fd_, LOCK_UN);
    ::close(fd_);
  }
}

void stage_text_file(AtomicOutput &out, const std::string &text) {
  std::FILE *f = std::fopen(out.temporary().c_str(), "wb");
  const bool ok = f && std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const bool closed = f && std::fclose(f) == 0;
  if (!ok || !closed) {
    const std::string cause = out.failure_cause();
    std::remove(out.temporary().c_str());
    throw ProcessingError("Cannot write '" + out.path() + "': " + cause + ". Free space or choose another folder; " +
                          (file_exists(out.path()) ? "the previous file is unchanged." : "nothing was written."));
  }
}

void write_text_file_atomically(const std::string &path, const std::string &text) {
  AtomicOutput out(path);
  stage_text_file(out, text);
  out.commit((long long)text.size());
}

} // namespace vbrdf
