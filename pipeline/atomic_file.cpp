#include "pipeline/atomic_file.h"

#include <unistd.h>

#include <fstream>

#include "pipeline/error.h"

namespace floesim {

AtomicFile::AtomicFile(std::filesystem::path final_path) : final_(std::move(final_path)) {
  tmp_ = final_.parent_path() / (".tmp-" + std::to_string(::getpid()) + "-" + final_.filename().string());
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void AtomicFile::commit() {
  std::error_code ec;
  std::filesystem::rename(tmp_, final_, ec);
  if (ec) throw Error(final_.string() + ": cannot move the finished file into place: " + ec.message());
  committed_ = true;
}

void write_text_atomic(const std::filesystem::path& path, const std::string& text) {
  AtomicFile f(path);
  {
    std::ofstream out(f.tmp(), std::ios::binary);
    if (!out) throw Error(path.string() + ": cannot write (is the directory writable?)");
    out << text;
    out.flush();
    if (!out) throw Error(path.string() + ": write failed (disk full?)");
  }
  f.commit();
}

void ensure_directory(const std::filesystem::path& dir) {
  if (dir.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw Error(dir.string() + ": cannot create the output directory: " + ec.message());
}

}  // namespace floesim
