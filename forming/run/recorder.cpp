#include "forming/run/recorder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <utility>

#include "common/cli/progress.hpp"
#include "common/core/error.hpp"
#include "common/io/json.hpp"
#include "forming/output/forming_results.hpp"
#include "forming/output/grid_out.hpp"
#include "forming/output/summary.hpp"

namespace sf::forming {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// The working folder OUT.partial holds the frames and restart.json of a run in progress;
// it survives a kill, and `--restart` continues in it. Committed, it replaces OUT whole:
// the outputs of an earlier run (its frames, series, history, summary) never stay beside
// those of this one; other files in OUT (the user's) are kept.
io::OutputDirOptions folder_options(const RunOptions& options) {
  io::OutputDirOptions o;
  o.owned = {"steps",        "result.pvd",     "history.csv", "summary.json", "restart.json",
             "profiles.csv", "tool_force.csv", "plots",       "report.html"};
  o.work_suffix = ".partial";
  // Continue in the working folder of a killed run when it got as far as a restart file.
  std::filesystem::path dir = std::filesystem::path(options.out_dir).lexically_normal();
  if (!dir.has_filename()) dir = dir.parent_path();  // "out/" -> "out"
  std::error_code ec;
  o.resume = options.restart && !options.out_dir.empty() &&
             std::filesystem::exists(std::filesystem::path(dir.string() + o.work_suffix) / "restart.json", ec);
  return o;
}

}  // namespace

RunRecorder::RunRecorder(const FormingCase& spec, Problem& problem, const RunOptions& options)
    : spec_(spec),
      problem_(problem),
      options_(options),
      X_(problem.model.reference_positions()),
      out_(options.out_dir, folder_options(options)),
      frames_(problem.model, spec.output.samples_inplane, spec.output.samples_thickness),
      history_(problem.model, tool_edge(spec, problem.model),
               spec.solver.stabilise_fraction > 0.0 || spec.solver.stabilise_damping > 0.0),
      restart_path_((out_.temp_dir() / "restart.json").string()),
      created_(Clock::now()) {
  report_.status = RunReport::Status::kConverged;
  stabilised_ = spec.solver.stabilise_fraction > 0.0 || spec.solver.stabilise_damping > 0.0;
}

SteppingState RunRecorder::start() {
  SteppingState state{X_, VecX::Zero(problem_.model.n_dofs()), 0.0};
  if (options_.restart) {
    // A killed run's working folder, or else the committed results (linked in whole).
    const bool killed_run = std::filesystem::exists(restart_path_);
    if (!killed_run) out_.seed_from_final();
    restart_ = read_restart(restart_path_, spec_, problem_.model);
    state.x = restart_.positions;
    if (spec_.solver.dynamic && restart_.velocities.size() == problem_.model.n_dofs()) state.v = restart_.velocities;
    if (restart_.predictor_rate.size() == problem_.model.n_dofs()) state.predictor_rate = restart_.predictor_rate;
    state.next_increment = restart_.next_increment;
    state.load_factor = restart_.load_factor;
    // Earlier frames (and their tool and contact parts) of this run stay in the collection;
    // they lie in the same folder as the restart file, so they are this run's own.
    int missing = 0;
    for (const auto& [lambda, name] : restart_.frames) {
      if (std::filesystem::exists(out_.temp_dir() / name))
        frames_.keep(lambda, name);
      else
        ++missing;
    }
    for (const io::PvdDataSet& part : restart_.parts) {
      if (std::filesystem::exists(out_.temp_dir() / part.file))
        frames_.keep_part(part);
      else
        ++missing;
    }
    try {
      history_.append_rows(restart_.history_rows);
    } catch (const InputError& e) {
      throw InputError(restart_path_ + ": " + e.what());
    }
    stabilisation_energy_ = restart_.stabilisation_energy;
    damping_ = restart_.stabilisation_damping;
    cli::status(options_.quiet, "simform: restarting from load factor " + std::to_string(state.load_factor) +
                                    " (step " + std::to_string(restart_.step) + " of the earlier run" +
                                    (killed_run ? ", from the folder of the interrupted run" : "") + ")");
    if (missing > 0)
      cli::status(options_.quiet, "simform: warning: " + std::to_string(missing) +
                                      " earlier frame files are missing; the series lists the others");
  } else {
    // The start state as given, nothing solved: no forces (history.hpp).
    history_.add_start_row(state.x);
    const Clock::time_point t0 = Clock::now();
    const InteractionContext at_rest{};
    frames_.write(out_, 0, 0.0, state.x, &at_rest);
    seconds_write_ += seconds_since(t0);
  }
  last_ = state;
  last_time_ = state.load_factor * (spec_.solver.dynamic ? spec_.solver.end_time : spec_.solver.process_time);
  start_load_factor_ = state.load_factor;
  stepping_started_ = Clock::now();
  return state;
}

InteractionContext RunRecorder::context() const {
  InteractionContext c;
  c.time = last_time_;
  if (spec_.solver.dynamic) c.velocity = &last_.v;
  if (have_previous_) {
    c.previous = &previous_.x;
    c.previous_time = previous_time_;
  }
  return c;
}

StepAction RunRecorder::on_step(const StepInfo& step, const SteppingState& state, const VecX& reactions) {
  previous_ = last_;
  previous_time_ = last_time_;
  have_previous_ = true;
  last_ = state;
  last_time_ = step.time;
  const ToolState tool = history_.add_row(step.index, step.load_factor, state.x, reactions, step.iterations,
                                          step.cutbacks, step.residual, context(), step.stabilisation_energy);
  if (step.stabilised) {
    stabilisation_energy_ = step.stabilisation_energy;
    damping_ = step.damping;
    const double strain = history_.last_strain_energy();
    ratio_ = strain > 0.0 ? stabilisation_energy_ / strain : 0.0;
    max_ratio_ = std::max(max_ratio_, ratio_);
    if (!warned_ && ratio_ > spec_.solver.stabilise_warn_ratio) {
      warned_ = true;
      cli::status(options_.quiet, "simform: warning: step " + std::to_string(step.index) +
                                      ": the stabilisation has dissipated " + sci(100.0 * ratio_) +
                                      " % of the strain energy (above warn_ratio " +
                                      sci(spec_.solver.stabilise_warn_ratio) +
                                      "): the results are not quasi-static; give a smaller fraction or damping");
    }
  }
  for (const BranchSwitch& b : step.branch_switches) {
    nlohmann::json shares = nlohmann::json::array();
    for (const double sh : b.place.shares) shares.push_back(std::round(10.0 * sh) / 10.0);
    branch_switches_.push_back({{"step", b.step},
                                {"load_factor", b.load_factor},
                                {"time", b.load_factor * spec_.solver.process_time},
                                {"after_failure", b.after_failure},
                                {"determinant_sign", b.determinant_sign},
                                {"eigenvalue", b.eigenvalue},
                                {"spread", b.spread},
                                {"amplitude", b.amplitude},
                                {"ply", b.place.ply},
                                {"x", b.place.x},
                                {"z", b.place.z},
                                {"ply_shares_percent", shares}});
    cli::status(options_.quiet, "simform: branch switch " + std::string(b.after_failure ? "in" : "after") +
                                    " step " + std::to_string(b.step) + " at load factor " + sci(b.load_factor) +
                                    ": det sign " + std::to_string(b.determinant_sign) + ", eigenvalue " +
                                    sci(b.eigenvalue) + " max|K_ii|, moved " + sci(b.amplitude) + " mm along the mode " +
                                    describe(b.place));
  }
  report_.max_displacement = largest_displacement(problem_.model, state.x, X_);
  report_.steps_converged = step.index;
  report_.load_factor = step.load_factor;
  report_.final_residual = step.residual;
  report_.tool_displacement = tool.displacement;
  report_.tool_force = tool.force;
  cli::status(options_.quiet, progress_line(step));

  // --stop-after and the last-step frame apply to load and time steps (an arc-length
  // run has no fixed last step and cannot restart).
  const bool fixed_steps = step.control != Control::kArcLength;
  ++steps_this_run_;
  const bool stop_now =
      fixed_steps && options_.stop_after > 0 && steps_this_run_ >= options_.stop_after && step.index < step.n_steps;
  if (step.index % spec_.output.every == 0 || (fixed_steps && step.index == step.n_steps) || stop_now)
    write_step(step.index, step.load_factor);
  if (!stop_now) return StepAction::kContinue;
  report_.status = RunReport::Status::kStopped;
  report_.message = "stopped after step " + std::to_string(step.index) + " of " + std::to_string(step.n_steps) +
                    " (--stop-after); continue with --restart";
  cli::status(options_.quiet, "simform: " + report_.message);
  return StepAction::kStop;
}

std::string RunRecorder::progress_line(const StepInfo& step) const {
  std::ostringstream os;
  if (step.control == Control::kArcLength) {
    os << "simform: arc-length step " << step.index << "  load factor " << step.load_factor << "  Newton "
       << step.iterations;
  } else {
    os << "simform: step " << step.index << "/" << step.n_steps;
    if (step.control == Control::kDynamic)
      os << "  t " << step.time << " s";
    else
      os << "  load factor " << step.load_factor;
    os << "  Newton " << step.iterations << (step.cutbacks ? " (" + std::to_string(step.cutbacks) + " cut-backs)" : "");
  }
  os << "  |r| " << sci(step.residual) << " N  max |u| " << sci(report_.max_displacement.norm()) << " mm";
  return os.str();
}

void RunRecorder::write_step(int k, double load_factor) {
  const Clock::time_point t0 = Clock::now();
  const InteractionContext c = context();
  frames_.write(out_, k, load_factor, last_.x, &c);
  last_written_ = k;
  restart_.step = k;
  restart_.load_factor = load_factor;
  restart_.positions = last_.x;
  restart_.velocities = spec_.solver.dynamic ? last_.v : VecX();
  restart_.predictor_rate = last_.predictor_rate;
  restart_.next_increment = last_.next_increment;
  restart_.history_rows = history_.rows();
  restart_.frames = frames_.frames();
  restart_.parts = frames_.parts();
  restart_.stabilisation_damping = damping_;
  restart_.stabilisation_energy = stabilisation_energy_;
  write_restart(restart_path_, spec_, problem_.model, restart_);
  seconds_write_ += seconds_since(t0);
}

RunReport RunRecorder::finish(const SteppingReport& stepping, double seconds_build) {
  const double seconds_stepping = seconds_since(stepping_started_);
  if (stepping.nothing_left) {  // a finished run restarted: nothing to step
    report_.steps_converged = spec_.solver.steps;
    report_.load_factor = start_load_factor_;
  }
  report_.total_iterations = stepping.total_iterations;
  report_.multiplier_updates = stepping.multiplier_updates;
  if (stepping.status == SteppingReport::Status::kFailed) {
    report_.status = RunReport::Status::kNotConverged;
    report_.message = stepping.message;
    if (!stepping.step_failure.empty()) cli::status(options_.quiet, "simform: " + stepping.step_failure);
  }
  // The last converged step is always in the series (a failed run's too).
  if (report_.status != RunReport::Status::kStopped && !stepping.nothing_left &&
      report_.steps_converged > last_written_)
    write_step(report_.steps_converged, report_.load_factor);
  const double seconds_solve = seconds_stepping - seconds_write_;

  // The grid file is written after the folder is committed (it may lie inside it).
  const bool converged = report_.status == RunReport::Status::kConverged;
  const bool write_grid_file = !options_.grid_out.empty() && converged;
  if (!options_.grid_out.empty() && !converged)
    cli::status(options_.quiet, "simform: not writing " + options_.grid_out + " (the run did not converge)");

  const Clock::time_point t_out = Clock::now();
  frames_.write_collection(out_.path("result.pvd"));
  io::write_file_atomic(out_.path("history.csv"), history_.text());
  // Forming results of the last converged state (forming_results.hpp).
  const double process_time = spec_.solver.dynamic ? spec_.solver.end_time : spec_.solver.process_time;
  io::write_file_atomic(out_.path("tool_force.csv"), tool_force_csv(history_.text(), "history.csv", process_time));
  io::write_file_atomic(out_.path("profiles.csv"), profiles_csv(spec_, problem_.model, last_.x));
  seconds_write_ += seconds_since(t_out);
  report_.seconds = seconds_build + seconds_since(created_);

  RunSummary s;
  s.command_line = options_.command_line;
  s.status = converged ? "converged" : report_.ok() ? "stopped" : "not_converged";
  s.message = converged ? report_.brief() : report_.message;
  s.follower_loads = problem_.loads.follower;
  s.load_factor = report_.load_factor;
  s.final_residual = report_.final_residual;
  s.newton_iterations = report_.total_iterations;
  s.multiplier_updates = report_.multiplier_updates;
  s.restarted = options_.restart;
  s.restart_load_factor = start_load_factor_;
  s.steps_converged = report_.steps_converged;
  s.tool_label = history_.tool().label;
  s.tool_displacement = report_.tool_displacement;
  s.tool_force = report_.tool_force;
  s.max_displacement = report_.max_displacement;
  s.frames = frames_.frames();
  s.seconds_build = seconds_build;
  s.seconds_solve = seconds_solve;
  s.seconds_write = seconds_write_;
  s.seconds_total = report_.seconds;
  s.grid_out = write_grid_file ? options_.grid_out : std::string();
  s.stabilised = stabilised_;
  s.stabilisation_energy = stabilisation_energy_;
  s.stabilisation_damping = damping_;
  s.stabilisation_ratio = ratio_;
  s.stabilisation_max_ratio = max_ratio_;
  s.branch_switches = branch_switches_;
  nlohmann::json summary = summary_json(spec_, problem_.model, s);
  summary["forming"] = forming_summary(spec_, problem_.model, last_.x, spec_.output.samples_inplane);
  io::write_json(out_.path("summary.json"), summary);
  out_.commit();

  if (write_grid_file) {
    const std::filesystem::path parent = std::filesystem::path(options_.grid_out).parent_path();
    std::error_code ec;
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    if (ec) throw Error(options_.grid_out + ": cannot create folder " + parent.string() + " (" + ec.message() + ")");
    const int body = options_.grid_ply.empty() ? 0 : spec_.find_ply(options_.grid_ply);
    write_grid(options_.grid_out, spec_, problem_.model, body, last_.x, options_.grid_marks);
  }
  return report_;
}

}  // namespace sf::forming
