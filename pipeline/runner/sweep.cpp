#include "pipeline/runner/sweep.h"

#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/interrupt.h"
#include "pipeline/options.h"
#include "pipeline/runner/plan.h"
#include "pipeline/runner/process.h"
#include "pipeline/sweep/sweep_plan.h"
#include "pipeline/runner/runner.h"

#ifndef FLOESIM_NINJA
#define FLOESIM_NINJA "ninja"
#endif

namespace fs = std::filesystem;

namespace floesim::runner {
namespace {

const std::vector<std::string> kCaseKeys = {"image", "digitise", "floes", "hull", "simulate", "render", "plot",
                                            "report"};

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string out;
  for (size_t i = 0; i < v.size(); ++i) out += (i ? sep : "") + v[i];
  return out;
}

void require_known_keys(const Json& j, const std::vector<std::string>& known, const std::string& file,
                        const std::string& where) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    bool ok = false;
    for (auto& k : known) ok = ok || k == it.key();
    FLOESIM_REQUIRE(ok, file, ": unknown key ", where, it.key(), " (known: ", join(known, ", "), ")");
  }
}

std::string value_text(const Json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

// "simulate.vessel.propulsion.speed_mps = 2, image.synthetic.seed = 3"
std::string describe(const Member& m) {
  std::vector<std::string> parts;
  for (auto it = m.axes.begin(); it != m.axes.end(); ++it) parts.push_back(it.key() + " = " + value_text(*it));
  for (auto it = m.seeds.begin(); it != m.seeds.end(); ++it) parts.push_back(it.key() + " = " + value_text(*it));
  return m.id + (parts.empty() ? "" : " (" + join(parts, ", ") + ")");
}

// The stages of all members, each distinct instance once, in dependency order; and which members use each.
struct SweepStages {
  std::vector<PlannedStage> stages;
  std::vector<std::vector<int>> users;        // stage -> members
  std::vector<std::vector<int>> member_stages;  // member -> stages, in run order
  std::vector<CasePlan> members;
};

SweepStages plan_members(const Sweep& s, const std::vector<Member>& members, const fs::path& run, const fs::path& bin) {
  StageLayout layout;
  layout.dir = [&](const std::string& stage, const std::string& key) { return run / "stages" / (stage + "-" + key); };
  layout.config = [&](const std::string& stage, const std::string& key) {
    return run / "stages" / (stage + "-" + key) / "config.json";
  };
  SweepStages p;
  std::map<std::string, int> index;  // key -> stage
  for (size_t m = 0; m < members.size(); ++m) {
    const std::string where = s.file.string() + " (member " + describe(members[m]) + ")";
    p.members.push_back(plan_case(members[m].case_json, where, s.base_dir, bin, layout, s.render));
    std::vector<int> mine;
    for (const PlannedStage& st : p.members.back().stages) {
      auto [it, fresh] = index.emplace(st.key, static_cast<int>(p.stages.size()));
      if (fresh) {
        p.stages.push_back(st);
        p.users.emplace_back();
      }
      p.users[it->second].push_back(static_cast<int>(m));
      mine.push_back(it->second);
    }
    p.member_stages.push_back(mine);
  }
  return p;
}

// Each distinct stage instance checks its own settings (`--check-config`), from a temporary copy: nothing of the
// run is written before the whole sweep is known to be valid. All problems are listed, one per instance.
void check_stage_settings(const Sweep& s, const std::vector<Member>& members, const SweepStages& p) {
  const std::vector<std::string> found = stage_settings_problems(p.stages);
  std::vector<std::string> problems;
  for (size_t k = 0; k < found.size(); ++k)
    if (!found[k].empty())
      problems.push_back("member " + describe(members[p.users[k][0]]) + ", stage " + p.stages[k].name + ": " +
                         found[k]);
  FLOESIM_REQUIRE(problems.empty(), s.file.string(), ": ", problems.size(),
                  " stage setting(s) refused, nothing was run:\n  ", join(problems, "\n  "));
}

// Each axis's label, unit and meaning from its option's own description: the stage whose settings section is the
// longest prefix of the axis key describes its options (`--describe-config`), asked once per executable. A key in no
// stage's settings (the case's own, such as image.metres_per_pixel) is named by its words.
void describe_axes(std::vector<sweep::PlanAxis>& axes, const std::vector<PlannedStage>& stages) {
  std::map<fs::path, Json> described;
  for (sweep::PlanAxis& a : axes) {
    const PlannedStage* owner = nullptr;
    for (const PlannedStage& st : stages)
      if (!st.section.empty() && a.key.rfind(st.section + ".", 0) == 0 &&
          (!owner || st.section.size() > owner->section.size()))
        owner = &st;
    if (!owner) {
      a.label = sweep::axis_label(a.key, "", "");
      continue;
    }
    auto it = described.find(owner->exe);
    if (it == described.end()) {
      const Output r = run_capture({owner->exe.string(), "--describe-config"});
      Json d;
      try {
        d = Json::parse(r.text);
      } catch (const std::exception&) {
      }
      FLOESIM_REQUIRE(r.code == 0 && d.is_object(), owner->exe.string(),
                      " --describe-config did not describe its options (exit ", r.code, "): ", r.text.substr(0, 300));
      it = described.emplace(owner->exe, std::move(d)).first;
    }
    const std::string field = a.key.substr(owner->section.size() + 1);
    const Json& d = it->second.value(sweep::list_item_path(field), Json::object());
    a.unit = d.value("unit", "");
    a.doc = d.value("doc", "");
    a.label = sweep::axis_label(field, a.unit, a.doc);
  }
}

// Writes what the run needs: stage settings, member folders (case.json and links to their stages' folders, named
// as in a run folder) and plan.json for floesim-gather.
void write_sweep_files(const Sweep& s, const std::vector<Member>& members, const SweepStages& p, const fs::path& run) {
  for (const PlannedStage& st : p.stages) {
    ensure_directory(st.dir);
    write_if_changed(st.config, st.config_text);
  }
  sweep::SweepPlan plan;
  plan.name = s.name;
  plan.sweep_file = fs::absolute(s.file).string();
  plan.base_case = fs::absolute(s.base_dir).lexically_normal().string();
  plan.combine = s.zip ? "zip" : "grid";
  for (const SweepAxis& a : s.axes) plan.axes.push_back({a.key, a.paths, a.values, "", "", ""});
  describe_axes(plan.axes, p.stages);
  Json vary = Json::array();
  if (s.vary_field_seed) vary.push_back("field_seed");
  if (s.vary_start) vary.push_back("start");
  plan.ensemble = {{"size", s.ensemble_size}, {"vary", vary}, {"start_step_m", s.start_step_m}};
  for (size_t m = 0; m < members.size(); ++m) {
    const Member& mb = members[m];
    if (mb.ensemble_index == 0) plan.grid_points.push_back({static_cast<size_t>(mb.grid_point), mb.axes});
    sweep::PlanMember pm;
    pm.id = mb.id;
    pm.grid_point = mb.grid_point;
    pm.ensemble_index = mb.ensemble_index;
    pm.axes = mb.axes;
    pm.seeds = mb.seeds;
    pm.dir = run / "members" / mb.id;
    pm.summary = p.members[m].summary;
    pm.results = p.members[m].results;
    ensure_directory(pm.dir);
    write_if_changed(pm.dir / "case.json", mb.case_json.dump(2) + "\n");
    for (int k : p.member_stages[m]) {
      const PlannedStage& st = p.stages[k];
      // A link replaced atomically: made under a temporary name, renamed over the old one.
      const fs::path link = pm.dir / run_folder(st.name), tmp = pm.dir / (run_folder(st.name) + ".tmp-link");
      std::error_code ec;
      fs::remove(tmp, ec);
      fs::create_directory_symlink(fs::path("../../stages") / st.dir.filename(), tmp);
      fs::rename(tmp, link);
      pm.stages.push_back({st.name, st.dir, st.outputs, st.dir / "log.txt", st.dir / "wall_ms"});
    }
    plan.members.push_back(std::move(pm));
  }
  write_if_changed(run / "plan.json", sweep::sweep_plan_json(plan).dump(2) + "\n");
}

// Ninja, keep going past failures (-k 0), with a progress line from NINJA_STATUS and the members' final outputs.
int run_ninja(const fs::path& run, int jobs, const std::vector<Member>& members, const SweepStages& p,
              std::vector<std::string>* interrupted_stages) {
  std::vector<std::string> args = {FLOESIM_NINJA, "-C", run.string(), "-f", "build.ninja", "-k", "0"};
  if (jobs > 0) args.push_back("-j" + std::to_string(jobs));
  Child ninja = spawn_piped(args, {{"NINJA_STATUS", "[%f/%t %r] "}});  // finished / total edges, running
  FILE* in = ninja.out;
  const bool tty = isatty(1);
  const auto t0 = std::chrono::steady_clock::now();
  std::set<int> failed_stages;
  std::string last_status;
  char line[65536];
  auto member_done = [&](size_t m) {
    for (int k : p.member_stages[m])
      for (const fs::path& o : p.stages[k].outputs)
        if (!fs::exists(o)) return false;
    return true;
  };
  std::vector<std::string> before;  // the stages running at the last status line before a stop signal
  auto running_now = [&] {
    std::vector<std::string> out;
    for (const PlannedStage* st : running_stages(ninja.pid, p.stages)) out.push_back(st->dir.filename().string());
    return out;
  };
  bool looked = false;
  const auto look = [&] {  // the stages a stop signal reaches, seen as soon as it arrives
    if (!interrupt_signal() || looked) return;
    *interrupted_stages = running_now();
    if (interrupted_stages->empty()) *interrupted_stages = before;
    looked = true;
  };
  while (read_line(in, line, sizeof line, look)) {
    look();
    std::string l(line);
    int finished = -1, total = 0, running = 0;
    if (std::sscanf(l.c_str(), "[%d/%d %d]", &finished, &total, &running) == 3) {
      if (!interrupt_signal()) before = running_now();
      int done = 0, failed = 0;
      for (size_t m = 0; m < members.size(); ++m) {
        bool f = false;
        for (int k : p.member_stages[m]) f = f || failed_stages.count(k);
        failed += f;
        done += !f && member_done(m);
      }
      const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::ostringstream st;
      st << "members " << done << "/" << members.size() << " done, " << failed << " failed; stages " << finished
         << "/" << total << ", " << running << " running";
      if (finished > 0 && finished < total) {
        const double left = el / finished * (total - finished);  // the stages done so far set the pace
        st << "; ~" << (left < 90 ? static_cast<int>(std::ceil(left)) : static_cast<int>(std::ceil(left / 60)))
           << (left < 90 ? " s" : " min") << " left";
      }
      if (tty) {
        std::cout << "\r" << st.str() << "   " << std::flush;
      } else if (st.str() != last_status) {
        std::cout << st.str() << "\n" << std::flush;
      }
      last_status = st.str();
      continue;
    }
    if (l.rfind("FAILED: ", 0) == 0) {
      // "FAILED: <outputs...>": the stage whose first output is named.
      for (size_t k = 0; k < p.stages.size(); ++k)
        if (l.find(p.stages[k].outputs[0].string()) != std::string::npos) failed_stages.insert(static_cast<int>(k));
    }
    // Commands and the failed stages' log tails: shown as they come (on a new line after a progress line).
    if (l.rfind("ninja: ", 0) == 0 && l.find("build stopped") == std::string::npos) continue;
    if (tty) std::cout << "\n";
    std::cout << l << std::flush;
  }
  if (interrupt_signal() && !looked) *interrupted_stages = before;
  const int code = wait_child(ninja);
  int done = 0;
  for (size_t m = 0; m < members.size(); ++m) done += member_done(m);
  const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << (tty ? "\n" : "") << "members " << done << "/" << members.size() << " complete, "
            << members.size() - done << " not; " << static_cast<int>(std::round(el)) << " s\n";
  return code;
}

// The gather stage: RUN/sweep.csv, sweep.json and plots from the members' results; then the sweep's report,
// RUN/report.html, with the base case's report settings (RUN/report_config.json).
std::vector<std::vector<std::string>> gather_commands(const fs::path& bin, const fs::path& run) {
  return {{(bin / "floesim-gather").string(), "--plan", (run / "plan.json").string(), "--out", run.string()},
          {(bin / "floesim-report").string(), "--sweep", run.string(), "--config",
           (run / "report_config.json").string(), "--out", (run / "report.html").string()}};
}

int gather(const fs::path& bin, const fs::path& run) {
  for (const auto& cmd : gather_commands(bin, run)) {
    std::cout.flush();
    const Output r = run_capture(cmd);
    std::cout << r.text;
    if (r.code != 0) return r.code;
  }
  return 0;
}

// The base case's report settings (its "report" section; the references the sweep's means are compared with),
// checked by floesim-report before anything runs.
void write_report_config(const Sweep& s, const Json& base, const fs::path& bin, const fs::path& run) {
  const Json cfg = base.contains("report") ? base["report"] : Json::object();
  ensure_directory(run);
  write_if_changed(run / "report_config.json", cfg.dump(2) + "\n");
  const Output r = run_capture({(bin / "floesim-report").string(), "--check-config", "--config",
                                (run / "report_config.json").string()});
  FLOESIM_REQUIRE(r.code == 0, (s.base_dir / "case.json").string(), ": its \"report\" section is refused:\n  ",
                  r.text);
}

// --- SLURM: one job array per level of the stage graph, each level after the one before (afterany: a failed
// member does not stop the others; its downstream stages fail on their missing inputs), then the gather job. ---

// Stages to run: an output missing or older than an input or the executable, or an input that will be remade.
std::vector<bool> stale_stages(const SweepStages& p) {
  std::vector<bool> stale(p.stages.size(), false);
  std::map<fs::path, size_t> producer;
  for (size_t k = 0; k < p.stages.size(); ++k)
    for (const fs::path& o : p.stages[k].outputs) producer[o] = k;
  for (size_t k = 0; k < p.stages.size(); ++k) {
    const PlannedStage& st = p.stages[k];
    fs::file_time_type newest_in = fs::last_write_time(st.exe);
    bool s = false;
    for (const fs::path& in : st.inputs) {
      auto it = producer.find(in);
      if (it != producer.end() && stale[it->second]) s = true;
      if (fs::exists(in)) newest_in = std::max(newest_in, fs::last_write_time(in));
    }
    for (const fs::path& o : st.outputs) s = s || !fs::exists(o) || fs::last_write_time(o) < newest_in;
    stale[k] = s;
  }
  return stale;
}

std::vector<int> stage_levels(const SweepStages& p) {
  std::vector<int> level(p.stages.size(), 0);
  std::map<fs::path, size_t> producer;
  for (size_t k = 0; k < p.stages.size(); ++k) {
    for (const fs::path& in : p.stages[k].inputs) {
      auto it = producer.find(in);
      if (it != producer.end()) level[k] = std::max(level[k], level[it->second] + 1);
    }
    for (const fs::path& o : p.stages[k].outputs) producer[o] = k;
  }
  return level;
}

std::string sbatch_job(const Sweep& s, const fs::path& run, const fs::path& script, const std::string& name,
                       int array_size, const std::string& after, bool wait) {
  std::vector<std::string> a = {"sbatch", "--parsable", "--job-name=" + name,
                                "--chdir=" + run.string(), "--time=" + s.slurm.time, "--mem=" + s.slurm.mem,
                                "--cpus-per-task=" + std::to_string(s.slurm.cpus_per_task)};
  if (array_size > 0) {
    a.push_back("--array=0-" + std::to_string(array_size - 1));
    a.push_back("--output=" + (run / "slurm" / "logs" / "%x_%A_%a.out").string());
  } else {
    a.push_back("--output=" + (run / "slurm" / "logs" / "%x_%j.out").string());
  }
  if (!s.slurm.partition.empty()) a.push_back("--partition=" + s.slurm.partition);
  if (!s.slurm.account.empty()) a.push_back("--account=" + s.slurm.account);
  if (!after.empty()) a.push_back("--dependency=afterany:" + after);
  if (wait) a.push_back("--wait");
  a.push_back(script.string());
  const Output r = run_capture(a);
  FLOESIM_REQUIRE(r.code == 0, "sbatch failed (exit ", r.code, ") submitting ", script.string(), ":\n", r.text,
                  "\nIs this a SLURM login node (sbatch in PATH, SLURM_CONF or /etc/slurm/slurm.conf)?");
  if (wait) return "";
  std::string id = r.text.substr(0, r.text.find_first_of(";\n"));
  FLOESIM_REQUIRE(!id.empty(), "sbatch gave no job id for ", script.string(), ": ", r.text);
  return id;
}

int submit_slurm(const Sweep& s, const fs::path& run, const fs::path& bin, const SweepStages& p, bool wait) {
  const std::vector<bool> stale = stale_stages(p);
  const std::vector<int> level = stage_levels(p);
  ensure_directory(run / "slurm" / "logs");
  int levels = 0;
  for (int l : level) levels = std::max(levels, l + 1);
  std::string after;
  for (int l = 0; l < levels; ++l) {
    std::vector<size_t> tasks;
    for (size_t k = 0; k < p.stages.size(); ++k)
      if (stale[k] && level[k] == l) tasks.push_back(k);
    if (tasks.empty()) continue;
    std::ostringstream sh;
    sh << "#!/bin/bash\n# floesim sweep " << s.name << ": level " << l << " of the stage graph, " << tasks.size()
       << " stage instance(s), one array task each. Written by floesim sweep --slurm; do not edit.\n"
       << "case \"$SLURM_ARRAY_TASK_ID\" in\n";
    for (size_t i = 0; i < tasks.size(); ++i)
      sh << i << ") # " << p.stages[tasks[i]].name << " " << p.stages[tasks[i]].key << "\n  "
         << stage_script(p.stages, tasks[i], StageOutput::logged) << " ;;\n";
    sh << "*) echo \"no task $SLURM_ARRAY_TASK_ID\" >&2; exit 2 ;;\nesac\n";
    const fs::path script = run / "slurm" / ("level" + std::to_string(l) + ".sh");
    write_text_atomic(script, sh.str());
    fs::permissions(script, fs::perms::owner_exec, fs::perm_options::add);
    after = sbatch_job(s, run, script, "floesim-" + s.name + "-L" + std::to_string(l),
                       static_cast<int>(tasks.size()), after, false);
    std::cout << "submitted level " << l << ": job array " << after << " (" << tasks.size() << " stage(s))\n";
  }
  const fs::path g = run / "slurm" / "gather.sh";
  std::string gather_sh = "#!/bin/bash\n# floesim sweep " + s.name + ": gather the members' results, then the report.\nset -e\n";
  for (const auto& cmd : gather_commands(bin, run)) {
    for (size_t i = 0; i < cmd.size(); ++i) gather_sh += (i ? " " : "") + shell_quote(cmd[i]);
    gather_sh += "\n";
  }
  write_text_atomic(g, gather_sh);
  fs::permissions(g, fs::perms::owner_exec, fs::perm_options::add);
  std::cout << "logs: " << (run / "slurm" / "logs").string() << "; stage logs: <stage folder>/log.txt\n";
  if (!wait) {
    const std::string id = sbatch_job(s, run, g, "floesim-" + s.name + "-gather", 0, after, false);
    std::cout << "submitted gather: job " << id << "; results in " << (run / "sweep.csv").string()
              << " when it has run (squeue -j " << id << ")\n";
    return 0;
  }
  std::cout << "submitted gather; waiting for the cluster to finish the sweep...\n" << std::flush;
  sbatch_job(s, run, g, "floesim-" + s.name + "-gather", 0, after, true);
  return 0;
}

// Members whose stages are not all complete (after a local run or a cluster run).
int report_failures(const std::vector<Member>& members, const SweepStages& p) {
  int failed = 0;
  for (size_t m = 0; m < members.size(); ++m) {
    for (int k : p.member_stages[m]) {
      const PlannedStage& st = p.stages[k];
      bool complete = true;
      for (const fs::path& o : st.outputs) complete = complete && fs::exists(o);
      if (complete) continue;
      ++failed;
      std::cerr << "FAILED member " << describe(members[m]) << " at stage " << st.name << " (log: "
                << (st.dir / "log.txt").string() << ")\n";
      break;
    }
  }
  if (failed)
    std::cerr << failed << " of " << members.size()
              << " member(s) failed; the others ran. Fix the cause and run the sweep again: only what is "
                 "missing or stale reruns.\n";
  return failed;
}

}  // namespace

void set_key_path(Json& c, const std::string& path, const Json& value, const std::string& where) {
  std::vector<std::string> parts;
  std::stringstream ss(path);
  for (std::string p; std::getline(ss, p, '.');) {
    FLOESIM_REQUIRE(!p.empty(), where, ": key path \"", path, "\" has an empty part");
    parts.push_back(p);
  }
  FLOESIM_REQUIRE(parts.size() >= 2, where, ": key path \"", path,
                  "\" must name a setting inside a case section (e.g. simulate.duration_s)");
  bool known = false;
  for (auto& k : kCaseKeys) known = known || k == parts[0];
  FLOESIM_REQUIRE(known, where, ": key path \"", path, "\": unknown case section \"", parts[0],
                  "\" (known: ", join(kCaseKeys, ", "), ")");
  // A part names a key of an object, or (all digits) an element of a list the case already has: simulate.ridges.0.
  Json* j = &c;
  std::string at;
  auto element = [&](const std::string& part) -> Json* {
    const bool digits = part.find_first_not_of("0123456789") == std::string::npos;
    FLOESIM_REQUIRE(digits && part.size() < 10 && std::stoul(part) < j->size(), where, ": key path \"", path, "\": ",
                    at, " is a list of ", j->size(), " in the case, and \"", part,
                    "\" is not the index of one of its elements (counted from 0)");
    return &(*j)[std::stoul(part)];
  };
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    if (j->is_array()) {
      j = element(parts[i]);
      at += "." + parts[i];
      continue;
    }
    at += (i ? "." : "") + parts[i];
    if (!j->contains(parts[i])) (*j)[parts[i]] = Json::object();
    FLOESIM_REQUIRE((*j)[parts[i]].is_object() || (*j)[parts[i]].is_array(), where, ": key path \"", path, "\": ",
                    at, " is not an object in the case");
    j = &(*j)[parts[i]];
  }
  if (j->is_array()) *element(parts.back()) = value;
  else (*j)[parts.back()] = value;
}

Sweep read_sweep(const fs::path& sweep_dir) {
  Sweep s;
  s.file = sweep_dir / "sweep.json";
  const std::string f = s.file.string();
  FLOESIM_REQUIRE(fs::is_regular_file(s.file), f, ": no sweep file (a sweep is a folder holding sweep.json)");
  const Json j = load_json_file(s.file);
  FLOESIM_REQUIRE(j.is_object(), f, ": the top level must be an object");
  require_known_keys(j, {"description", "base", "axes", "combine", "ensemble", "set", "render", "slurm"}, f, "");
  s.name = fs::absolute(sweep_dir).lexically_normal().filename().string();
  if (s.name.empty()) s.name = fs::absolute(sweep_dir).lexically_normal().parent_path().filename().string();
  if (j.contains("description")) {
    FLOESIM_REQUIRE(j["description"].is_string(), f, ": description must be a string");
    s.description = j["description"];
  }
  FLOESIM_REQUIRE(j.contains("base") && j["base"].is_string(), f,
                  ": \"base\" must name the base case folder (e.g. \"../default\")");
  s.base_dir = (fs::absolute(sweep_dir) / j["base"].get<std::string>()).lexically_normal();
  FLOESIM_REQUIRE(fs::is_regular_file(s.base_dir / "case.json"), f, ": base names ", s.base_dir.string(),
                  ", which holds no case.json");
  if (j.contains("axes")) {
    FLOESIM_REQUIRE(j["axes"].is_array(), f, ": axes must be a list of {\"key\": ..., \"values\": [...]}");
    for (size_t i = 0; i < j["axes"].size(); ++i) {
      const Json& a = j["axes"][i];
      const std::string w = "axes[" + std::to_string(i) + "]";
      FLOESIM_REQUIRE(a.is_object(), f, ": ", w, " must be an object {\"key\": ..., \"values\": [...]}");
      require_known_keys(a, {"key", "keys", "values"}, f, w + ".");
      FLOESIM_REQUIRE(a.contains("key") != a.contains("keys"), f, ": ", w,
                      " needs exactly one of \"key\" (a key path) or \"keys\" (several, set to the same value)");
      SweepAxis ax;
      if (a.contains("key")) {
        FLOESIM_REQUIRE(a["key"].is_string(), f, ": ", w, ".key must be a key path string");
        ax.paths.push_back(a["key"]);
      } else {
        FLOESIM_REQUIRE(a["keys"].is_array() && !a["keys"].empty(), f, ": ", w, ".keys must be a list of key paths");
        for (const Json& k : a["keys"]) {
          FLOESIM_REQUIRE(k.is_string(), f, ": ", w, ".keys must be a list of key path strings");
          ax.paths.push_back(k);
        }
      }
      ax.key = ax.paths[0];
      FLOESIM_REQUIRE(a.contains("values") && a["values"].is_array(), f, ": ", w, ".values must be a list");
      FLOESIM_REQUIRE(!a["values"].empty(), f, ": ", w, " (", ax.key, ") has no values: give at least one");
      for (const Json& v : a["values"]) ax.values.push_back(v);
      for (const SweepAxis& other : s.axes)
        FLOESIM_REQUIRE(other.key != ax.key, f, ": axis ", ax.key, " is given twice");
      s.axes.push_back(ax);
    }
  }
  if (j.contains("combine")) {
    FLOESIM_REQUIRE(j["combine"] == "grid" || j["combine"] == "zip", f,
                    ": combine must be \"grid\" (every combination) or \"zip\" (axes taken together)");
    s.zip = j["combine"] == "zip";
  }
  if (s.zip)
    for (const SweepAxis& a : s.axes)
      FLOESIM_REQUIRE(a.values.size() == s.axes[0].values.size(), f, ": combine \"zip\" needs axes of equal length (",
                      s.axes[0].key, " has ", s.axes[0].values.size(), ", ", a.key, " has ", a.values.size(), ")");
  if (j.contains("ensemble")) {
    const Json& e = j["ensemble"];
    FLOESIM_REQUIRE(e.is_object(), f, ": ensemble must be an object {\"size\": N, \"vary\": [...]}");
    require_known_keys(e, {"size", "vary", "start_step_m"}, f, "ensemble.");
    FLOESIM_REQUIRE(e.contains("size") && e["size"].is_number_integer() && e["size"].get<int>() >= 1, f,
                    ": ensemble.size must be an integer >= 1");
    s.ensemble_size = e["size"];
    FLOESIM_REQUIRE(e.contains("vary") && e["vary"].is_array() && !e["vary"].empty(), f,
                    ": ensemble.vary must list what changes between members: \"field_seed\" "
                    "(image.synthetic.seed + k) and/or \"start\" (simulate.vessel.y_m + k start_step_m)");
    for (const Json& v : e["vary"]) {
      FLOESIM_REQUIRE(v == "field_seed" || v == "start", f, ": ensemble.vary: unknown ", v.dump(),
                      " (known: field_seed, start)");
      (v == "field_seed" ? s.vary_field_seed : s.vary_start) = true;
    }
    if (e.contains("start_step_m")) {
      FLOESIM_REQUIRE(e["start_step_m"].is_number() && e["start_step_m"].get<double>() > 0, f,
                      ": ensemble.start_step_m must be a number > 0 (metres between starts)");
      s.start_step_m = e["start_step_m"];
    }
  }
  if (j.contains("set")) {
    FLOESIM_REQUIRE(j["set"].is_object(), f, ": set must be an object {\"key.path\": value}");
    s.set = j["set"];
  }
  if (j.contains("render")) {
    FLOESIM_REQUIRE(j["render"].is_boolean(), f, ": render must be true or false");
    s.render = j["render"];
  }
  if (j.contains("slurm")) {
    const Json& sl = j["slurm"];
    FLOESIM_REQUIRE(sl.is_object(), f, ": slurm must be an object");
    require_known_keys(sl, {"partition", "account", "time", "mem", "cpus_per_task"}, f, "slurm.");
    for (auto [key, field] : {std::pair{"partition", &s.slurm.partition}, std::pair{"account", &s.slurm.account},
                              std::pair{"time", &s.slurm.time}, std::pair{"mem", &s.slurm.mem}})
      if (sl.contains(key)) {
        FLOESIM_REQUIRE(sl[key].is_string(), f, ": slurm.", key, " must be a string");
        *field = sl[key];
      }
    if (sl.contains("cpus_per_task")) {
      FLOESIM_REQUIRE(sl["cpus_per_task"].is_number_integer() && sl["cpus_per_task"].get<int>() >= 1, f,
                      ": slurm.cpus_per_task must be an integer >= 1");
      s.slurm.cpus_per_task = sl["cpus_per_task"];
    }
  }
  return s;
}

std::vector<Member> expand_members(const Sweep& s, const Json& base_case) {
  const std::string f = s.file.string();
  Json base = base_case;
  for (auto it = s.set.begin(); it != s.set.end(); ++it) set_key_path(base, it.key(), *it, f + ": set." + it.key());
  // Grid points: every combination (the last axis fastest) or the axes' values taken together.
  std::vector<std::vector<size_t>> points;
  if (s.axes.empty()) {
    points.push_back({});
  } else if (s.zip) {
    for (size_t i = 0; i < s.axes[0].values.size(); ++i) points.push_back(std::vector<size_t>(s.axes.size(), i));
  } else {
    std::vector<size_t> idx(s.axes.size(), 0);
    while (true) {
      points.push_back(idx);
      size_t a = s.axes.size();
      while (a > 0 && ++idx[a - 1] == s.axes[a - 1].values.size()) idx[--a] = 0;
      if (a == 0) break;
    }
  }
  auto number_at = [&](const Json& c, const std::string& path, const char* what) {
    const Json* j = &c;
    std::stringstream ss(path);
    for (std::string p; std::getline(ss, p, '.');) {
      FLOESIM_REQUIRE(j->is_object() && j->contains(p), f, ": ensemble.vary ", what, " needs ", path,
                      " in the base case (set it there or under \"set\")");
      j = &(*j)[p];
    }
    FLOESIM_REQUIRE(j->is_number(), f, ": ensemble.vary ", what, ": ", path, " must be a number, got ", j->dump());
    return *j;
  };
  std::vector<Member> out;
  for (size_t g = 0; g < points.size(); ++g) {
    Json c = base;
    Json axes = Json::object();
    for (size_t a = 0; a < s.axes.size(); ++a) {
      const Json& v = s.axes[a].values[points[g][a]];
      for (const std::string& path : s.axes[a].paths) set_key_path(c, path, v, f + ": axis " + s.axes[a].key);
      axes[s.axes[a].key] = v;
    }
    for (int e = 0; e < s.ensemble_size; ++e) {
      Member m;
      char id[64];
      std::snprintf(id, sizeof id, "g%03zu-e%02d", g, e);
      m.id = id;
      m.grid_point = static_cast<int>(g);
      m.ensemble_index = e;
      m.axes = axes;
      m.case_json = c;
      if (s.vary_field_seed) {
        const Json seed = number_at(c, "image.synthetic.seed", "field_seed");
        FLOESIM_REQUIRE(seed.is_number_integer(), f, ": image.synthetic.seed must be an integer");
        m.seeds["image.synthetic.seed"] = seed.get<int64_t>() + e;
      }
      if (s.vary_start) {
        const double y = number_at(c, "simulate.vessel.y_m", "start").get<double>();
        m.seeds["simulate.vessel.y_m"] = y + e * s.start_step_m;
      }
      for (auto it = m.seeds.begin(); it != m.seeds.end(); ++it)
        set_key_path(m.case_json, it.key(), *it, f + ": ensemble");
      absolute_case_files(m.case_json, s.base_dir);  // a member's case.json runs from its own folder too
      out.push_back(m);
    }
  }
  return out;
}

int run_sweep(const SweepOptions& o) {
  // A stop signal is passed on to the children (ninja, and through it the stages); this process reports it.
  InterruptPolling polling;
  const Sweep s = read_sweep(o.sweep_dir);
  const Json base = load_json_file(s.base_dir / "case.json");
  const std::vector<Member> members = expand_members(s, base);
  FLOESIM_REQUIRE(o.yes || static_cast<int>(members.size()) <= kMaxMembersUnasked, s.file.string(), ": ",
                  members.size(), " members (", std::max<size_t>(1, members.size() / s.ensemble_size),
                  " grid points x ", s.ensemble_size, " starts) is more than ", kMaxMembersUnasked,
                  ": check the axes, and pass --yes to run them all");
  const fs::path run = fs::absolute(o.run_dir);
  const fs::path bin = o.bin_dir.empty() ? self_dir() : fs::absolute(o.bin_dir);
  const SweepStages p = plan_members(s, members, run, bin);
  check_stage_settings(s, members, p);  // writes nothing in the run folder
  // One writer at a time in the run folder (see lock_run_folder), taken before anything is written there.
  const int lock = lock_run_folder(run);
  (void)lock;
  write_report_config(s, base, bin, run);

  write_sweep_files(s, members, p, run);
  std::vector<std::string> descriptions;
  for (size_t k = 0; k < p.stages.size(); ++k) {
    const auto& u = p.users[k];
    descriptions.push_back(p.stages[k].name + " " + members[u[0]].id +
                           (u.size() > 1 ? " (shared by " + std::to_string(u.size()) + " members)" : ""));
  }
  write_ninja(run / "build.ninja", "# Generated by floesim sweep from " + fs::absolute(s.file).string() +
                                       "; do not edit.\n",
              p.stages, descriptions, StageOutput::logged);
  std::cout << "sweep " << s.name << ": " << members.size() << " member(s), " << p.stages.size()
            << " distinct stage instance(s) (" << [&] {
                 size_t n = 0;
                 for (const CasePlan& c : p.members) n += c.stages.size();
                 return n;
               }() << " without sharing), in " << run.string() << "\n";
  if (o.dry_run) {
    const Output r = run_capture({FLOESIM_NINJA, "-C", run.string(), "-f", "build.ninja", "-n"});
    std::cout << r.text;
    return r.code;
  }
  // Members' simulations continue from their checkpoints: FLOESIM_RESUME reaches the stage commands through ninja
  // here, and through sbatch's exported environment on a cluster.
  if (o.resume) setenv("FLOESIM_RESUME", "1", 1);
  if (o.slurm) {
    submit_slurm(s, run, bin, p, o.wait);
    if (!o.wait) return 0;
    return report_failures(members, p) ? 1 : 0;
  }
  // Temporaries of the runner's own files that a killed run left (each stage removes its own), under the lock.
  remove_stale_temporaries(run);
  std::vector<std::string> interrupted;
  if (!interrupt_signal()) run_ninja(run, o.jobs, members, p, &interrupted);
  if (const int sig = interrupt_signal()) {
    remove_stale_temporaries(run);
    std::cerr << "floesim: interrupted by " << signal_name(sig)
              << (interrupted.empty() ? std::string(" between stages") : " during stage " + join(interrupted, ", "))
              << "; nothing half-written left; nothing gathered; rerun to continue: floesim sweep "
              << o.sweep_dir.string() << " --out " << o.run_dir.string()
              << " (add --resume to continue the simulations from their checkpoints)\n";
    return 128 + sig;
  }
  const int g = gather(bin, run);
  const int failed = report_failures(members, p);
  if (g != 0) std::cerr << "floesim: gathering the results failed (exit " << g << ")\n";
  return failed || g ? 1 : 0;
}

}  // namespace floesim::runner
