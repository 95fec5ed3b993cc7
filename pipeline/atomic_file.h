// Artefacts are written to a temporary name beside the final one and renamed when complete, so a crash, a kill or
// a failed stage never leaves a file that looks finished. The temporary name keeps the extension, because
// OpenCV and others choose the format from it. Before the rename the file's data are forced to the disk (fsync):
// a full disk that the file system reports only at write-back (delayed allocation) fails the commit with a clear
// error instead of leaving a short file under the final name, and a power cut cannot leave an empty file under it.
#pragma once
#include <filesystem>
#include <string>

namespace floesim {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path final_path);
  ~AtomicFile();  // removes the temporary file if commit() was not reached
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::filesystem::path& tmp() const { return tmp_; }
  const std::filesystem::path& path() const { return final_; }
  // fsync tmp, then rename tmp -> final (atomic on one file system). Error naming the file if either fails.
  void commit();

 private:
  std::filesystem::path final_, tmp_;
  bool committed_ = false;
};

// Writes text to `path` atomically.
void write_text_atomic(const std::filesystem::path& path, const std::string& text);

// Writes bytes to `file` directly (for a file that is itself an AtomicFile's temporary), checking every write and
// the close; errors name `shown` (the final name) and say why (disk full, read-only, permissions).
void write_file_checked(const std::filesystem::path& file, const std::string& bytes,
                        const std::filesystem::path& shown);

// Makes the directory (and parents) and checks that a file can be created in it; errors name the directory, the
// reason and the fix.
void ensure_directory(const std::filesystem::path& dir);

// "No space left on device: free space or write elsewhere" and the like: the system's reason for errno `err` and
// what to do about it, for error messages.
std::string write_failure_reason(int err);

// Why a file another program wrote in `dir` (gnuplot, the video encoder, which do not report write errors) came out
// cut short: the full disk, said as write_failure_reason(ENOSPC) does, when less than 1 MiB is left there; else a
// question.
std::string cut_short_reason(const std::filesystem::path& dir);

}  // namespace floesim
