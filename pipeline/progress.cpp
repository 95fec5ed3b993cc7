#include "pipeline/progress.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>

namespace floesim {

ProgressLine::ProgressLine(std::ostream* out, long total)
    : out_(out), total_(total), overwrite_(out == &std::cout && isatty(STDOUT_FILENO) == 1) {}

bool ProgressLine::due(long done) const {
  return out_ && total_ > 0 && done < total_ && (done * 10) % total_ < 10;
}

std::string time_left(double wall_s, double fraction) {
  if (!(fraction > 0) || !std::isfinite(wall_s)) return "? s";
  const double left = wall_s * (1 - fraction) / fraction;
  char buf[64];
  if (left < 100) std::snprintf(buf, sizeof buf, "%.1f s", left);
  else if (left < 3600) std::snprintf(buf, sizeof buf, "%d min %02d s", int(left / 60), int(std::fmod(left, 60)));
  else std::snprintf(buf, sizeof buf, "%d h %02d min", int(left / 3600), int(std::fmod(left, 3600) / 60));
  return buf;
}

void ProgressLine::print(long done, double wall_s, const std::string& head, const std::string& tail) {
  if (!out_) return;
  const double fraction = static_cast<double>(done) / static_cast<double>(total_);
  char buf[96];
  std::snprintf(buf, sizeof buf, " (%ld %%, %.1f s wall, ", (done * 100) / total_, wall_s);
  *out_ << (overwrite_ ? "\r\033[K" : "") << "  " << head << buf << time_left(wall_s, fraction) << " left" << tail
        << ")";
  if (overwrite_) *out_ << std::flush;
  else *out_ << std::endl;
  open_line_ = overwrite_;
}

ProgressLine::~ProgressLine() {
  if (out_ && open_line_) *out_ << std::endl;
}

}  // namespace floesim
