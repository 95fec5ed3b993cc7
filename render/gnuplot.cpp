#include "render/gnuplot.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/interrupt.h"

extern char** environ;

namespace floesim::render {

namespace fs = std::filesystem;

#ifndef FLOESIM_GNUPLOT
#error "FLOESIM_GNUPLOT (the gnuplot executable) must be defined by the build"
#endif

std::string gnuplot_quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

namespace {

// Runs a program without a shell, stdout and stderr into `log`; returns its exit status.
int run_program(const std::vector<std::string>& args, const fs::path& log) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, args[0].c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  FLOESIM_REQUIRE(rc == 0, "cannot start ", args[0], ": ", std::strerror(rc));
  register_child(pid);  // killed by the stop-signal handler before it removes the files gnuplot writes
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    FLOESIM_REQUIRE(errno == EINTR, "waiting for ", args[0], " failed: ", std::strerror(errno));
  unregister_child(pid);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

void run_gnuplot(const fs::path& script, const fs::path& log, const std::vector<fs::path>& images,
                 const std::string& what) {
  const int rc = run_program({FLOESIM_GNUPLOT, script.string()}, log);
  FLOESIM_REQUIRE(rc == 0, "gnuplot (", FLOESIM_GNUPLOT, ") failed with exit status ", rc, " drawing ", what, ":\n",
                  read_text(log));
  for (const fs::path& image : images) {
    std::error_code ec;
    // An empty or missing image after exit 0 is a write that failed, most often for a full disk: say which.
    FLOESIM_REQUIRE(fs::file_size(image, ec) > 0 && !ec, image.string(), ": gnuplot wrote no image drawing ", what,
                    ": ", cut_short_reason(image.parent_path()), "\n", read_text(log));
    // gnuplot may exit 0 after a failed write (a full disk): the image must be whole, a PNG that decodes, an
    // SVG that ends.
    if (image.extension() == ".png")
      FLOESIM_REQUIRE(!cv::imread(image.string(), cv::IMREAD_UNCHANGED).empty(), what,
                      ": gnuplot's PNG does not decode: ", cut_short_reason(image.parent_path()));
    if (image.extension() == ".svg")
      FLOESIM_REQUIRE(read_text(image).find("</svg>") != std::string::npos, what, ": gnuplot's SVG is cut short: ",
                      cut_short_reason(image.parent_path()));
  }
}

}  // namespace floesim::render
