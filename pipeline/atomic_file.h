// Artefacts are written to a temporary name beside the final one and renamed when complete, so a crash or a
// failed stage never leaves a file that looks finished. The temporary name keeps the extension, because
// OpenCV and others choose the format from it.
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
  void commit();  // rename tmp -> final (atomic on one file system)

 private:
  std::filesystem::path final_, tmp_;
  bool committed_ = false;
};

// Writes text to `path` atomically.
void write_text_atomic(const std::filesystem::path& path, const std::string& text);

// Makes the directory (and parents); errors name the directory.
void ensure_directory(const std::filesystem::path& dir);

}  // namespace floesim
