#include "pipeline/atomic_file.h"

#include <fcntl.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "pipeline/error.h"
#include "pipeline/interrupt.h"

namespace floesim {

std::string write_failure_reason(int err) {
  std::string r = std::strerror(err);
  switch (err) {
    case ENOSPC:
    case EDQUOT: return r + " (the disk is full: free space there, or write the run to another folder)";
    case EROFS: return r + " (write the run to a writable folder, e.g. --out elsewhere)";
    case EACCES:
    case EPERM: return r + " (make the folder writable for this user, or write the run elsewhere)";
    case ENOTDIR: return r + " (a file stands where a folder of the path should be: choose another path)";
    default: return r;
  }
}

std::string cut_short_reason(const std::filesystem::path& dir) {
  struct statvfs st;
  const bool full = ::statvfs(dir.empty() ? "." : dir.c_str(), &st) == 0 &&
                    static_cast<double>(st.f_bavail) * static_cast<double>(st.f_frsize) < (1 << 20);
  return full ? write_failure_reason(ENOSPC) : std::string("is the disk full?");
}

AtomicFile::AtomicFile(std::filesystem::path final_path) : final_(std::move(final_path)) {
  tmp_ = final_.parent_path() / (".tmp-" + std::to_string(::getpid()) + "-" + final_.filename().string());
  register_temporary(tmp_);  // removed by the signal handler if the process is stopped at once
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
  unregister_temporary(tmp_);
}

void AtomicFile::commit() {
  // The data on the disk before the name: a file system that reports a full disk only at write-back reports it
  // here, and the rename never publishes a short file.
  const int fd = ::open(tmp_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw Error(final_.string() + ": the finished file is gone before it could be moved into place: " +
                          std::strerror(errno));
  const int rc = ::fsync(fd), err = errno;
  ::close(fd);
  if (rc != 0) throw Error(final_.string() + ": writing failed: " + write_failure_reason(err));
  std::error_code ec;
  std::filesystem::rename(tmp_, final_, ec);
  if (ec) throw Error(final_.string() + ": cannot move the finished file into place: " + ec.message());
  committed_ = true;
}

void write_file_checked(const std::filesystem::path& file, const std::string& bytes,
                        const std::filesystem::path& shown) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw Error(shown.string() + ": cannot write: " + write_failure_reason(errno));
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = n < 0 ? errno : ENOSPC;
      ::close(fd);
      throw Error(shown.string() + ": writing failed: " + write_failure_reason(err));
    }
    done += static_cast<size_t>(n);
  }
  if (::close(fd) != 0) throw Error(shown.string() + ": writing failed: " + write_failure_reason(errno));
}

void write_text_atomic(const std::filesystem::path& path, const std::string& text) {
  AtomicFile f(path);
  write_file_checked(f.tmp(), text, path);
  f.commit();
}

void ensure_directory(const std::filesystem::path& dir) {
  if (dir.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw Error(dir.string() + ": cannot create the output directory: " +
                (ec ? write_failure_reason(ec.value()) : std::string("a file of that name is in the way")));
  // A folder that exists may still refuse files (read-only mount, permissions): say so now, before hours of work
  // whose result could not be written.
  const std::filesystem::path probe = dir / (".tmp-" + std::to_string(::getpid()) + "-write-probe");
  register_temporary(probe);  // a stop signal in between removes it too
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  const int err = errno;
  if (fd >= 0) {
    ::close(fd);
    ::unlink(probe.c_str());
  }
  unregister_temporary(probe);
  if (fd < 0 && err != EEXIST)
    throw Error(dir.string() + ": cannot write in the output directory: " + write_failure_reason(err));
}

}  // namespace floesim
