// The progress line of a long stage loop (simulate's steps, render's frames): every 10 % of the work, what is done,
// the wall time so far and the time left at the rate so far. On a terminal each line overwrites the last ('\r'),
// in a log (a pipe or a file) each is a line of its own.
#pragma once
#include <iosfwd>
#include <string>

namespace floesim {

class ProgressLine {
 public:
  // `out` may be null (nothing printed); `total` units of work (steps, frames).
  ProgressLine(std::ostream* out, long total);
  // True when `done` (1 .. total) is the first unit of a new 10 % (never at the end: the stage's result follows).
  bool due(long done) const;
  // "  <head> (40 %, 12.3 s wall, 18.5 s left<tail>)" for `done` of the total after `wall_s` seconds.
  void print(long done, double wall_s, const std::string& head, const std::string& tail = "");
  // Ends an overwritten line (a newline), so that what follows starts on its own.
  ~ProgressLine();

 private:
  std::ostream* out_;
  long total_;
  bool overwrite_;
  bool open_line_ = false;
};

// "18.5 s", "4 min 10 s", "2 h 05 min": the time left after `wall_s` seconds for `fraction` (0, 1] of the work.
std::string time_left(double wall_s, double fraction);

}  // namespace floesim
