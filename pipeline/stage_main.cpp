#include "pipeline/stage_main.h"

#include <iostream>

#include "pipeline/error.h"
#include "pipeline/interrupt.h"
#include "pipeline/provenance.h"

namespace floesim {

void add_describe_config(CLI::App& app, std::function<nlohmann::json()> describe) {
  app.add_flag_callback(
      "--describe-config",
      [describe = std::move(describe)] {
        std::cout << describe().dump(2) << "\n";
        throw CLI::Success();
      },
      "print every option's key path with its unit and meaning as JSON (for programs) and exit");
}

int run_stage(CLI::App& app, int argc, char** argv, const std::function<void()>& body) {
  app.set_version_flag("--version", std::string(app.get_name()) + " (floesim) " + version());
  // SIGINT, SIGTERM, SIGHUP: stop without leaving a half-written file (pipeline/interrupt.h).
  install_interrupt_handlers();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    body();
    return 0;
  } catch (const Interrupted& e) {
    // Temporary files are gone with their AtomicFiles (the stack has unwound): nothing half-written is left.
    std::cerr << app.get_name() << ": " << e.what() << "; no half-written artefact left\n";
    return 128 + e.signal();
  } catch (const Error& e) {
    std::cerr << app.get_name() << ": error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << app.get_name() << ": internal error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace floesim
