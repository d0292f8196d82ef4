#include "gsa/batch.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/csv.hpp"
#include "common/io/json.hpp"

extern char** environ;

namespace sf::gsa {

namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr const char* kLogsFolder = "logs";
// The first line of a part's log names its input (for --collect of a part that failed).
constexpr const char* kLogInputLine = "# gsa batch input: ";

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

bool is_grid_file_name(const fs::path& p) {
  const std::string name = p.filename().string();
  if (name.empty() || name[0] == '.') return false;
  const std::string ext = lower(p.extension().string());
  return ext == ".csv" || ext == ".txt" || ext == ".tsv" || ext == ".dat";
}

// A part's name: the file's stem, or its folder's name for ".../NAME/grid.csv".
std::string part_name_of(const fs::path& file) {
  const std::string stem = file.stem().string();
  if (lower(stem) == "grid") {
    const std::string parent = fs::absolute(file).parent_path().filename().string();
    if (!parent.empty()) return parent;
  }
  return stem;
}

// The words of an `options` file (lines starting with '#' skipped).
std::vector<std::string> read_options_file(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot read");
  std::string line, text;
  while (std::getline(in, line))
    if (trim(line).rfind('#', 0) != 0) text += line + " ";
  try {
    return split_options(text);
  } catch (const UsageError& e) {
    throw InputError(path.string() + ": " + e.what());
  }
}

// The error of a failed part from its log: the last "gsa: ..." line (the runs are quiet, so
// that is the error), without "gsa: error: "; else the last non-blank line (a crash).
std::string error_from_log(const fs::path& log) {
  std::ifstream in(log);
  if (!in) return {};
  std::string line, last, last_gsa;
  while (std::getline(in, line)) {
    // Progress bars redraw with carriage returns: keep what follows the last one.
    const auto cr = line.find_last_of('\r');
    if (cr != std::string::npos) line = line.substr(cr + 1);
    line = trim(line);
    if (line.empty() || line.rfind(kLogInputLine, 0) == 0) continue;
    last = line;
    if (line.rfind("gsa: ", 0) == 0 && line.rfind("Run 'gsa", 0) != 0) last_gsa = line.substr(5);
  }
  if (last_gsa.empty()) return last;
  return last_gsa.rfind("error: ", 0) == 0 ? last_gsa.substr(7) : last_gsa;
}

// The input named by the log's first line (kLogInputLine), or "".
std::string input_from_log(const fs::path& log) {
  std::ifstream in(log);
  std::string line;
  if (in && std::getline(in, line) && line.rfind(kLogInputLine, 0) == 0)
    return trim(line.substr(std::strlen(kLogInputLine)));
  return {};
}

std::string major_column(const std::string& measure) {
  const std::string m = lower(measure);
  if (m == "engineering" || m == "eng") return "eng1";
  if (m == "lagrangian" || m == "green") return "E1";
  return "true1";
}

std::string measure_word(const std::string& measure) {
  const std::string c = major_column(measure);
  return c == "eng1" ? "engineering" : c == "E1" ? "lagrangian" : "true";
}

std::string signal_text(int sig) {
  const char* name = strsignal(sig);
  return "killed by signal " + std::to_string(sig) + (name ? std::string(" (") + name + ")" : std::string());
}

volatile std::sig_atomic_t g_interrupted = 0;
void on_interrupt(int) { g_interrupted = 1; }

}  // namespace

std::vector<std::string> split_options(const std::string& text) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  char quote = 0;
  for (char c : text) {
    if (quote) {
      if (c == quote)
        quote = 0;
      else
        word += c;
    } else if (c == '"' || c == '\'') {
      quote = c;
      in_word = true;
    } else if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
      if (in_word) words.push_back(word), word.clear(), in_word = false;
    } else {
      word += c;
      in_word = true;
    }
  }
  if (quote) throw UsageError(std::string("--options: unclosed quote ") + quote + " in '" + text + "'");
  if (in_word) words.push_back(word);
  return words;
}

std::vector<BatchPart> batch_parts(const std::string& list_or_folder) {
  std::vector<BatchPart> parts;
  std::map<std::string, std::string> where;  // part name -> where it came from, for messages
  auto add = [&](BatchPart part, const std::string& at) {
    if (part.name == kLogsFolder || part.name == "batch.csv")
      throw InputError(at + ": part name '" + part.name + "' is reserved for the batch's own files; rename " +
                       part.input);
    const auto [it, fresh] = where.emplace(part.name, at);
    if (!fresh)
      throw InputError(at + ": part name '" + part.name + "' (from " + part.input + ") is also the name of " +
                       it->second + "; each part needs its own name (its results folder): rename one of the files");
    parts.push_back(std::move(part));
  };
  const fs::path root(list_or_folder);
  std::error_code ec;
  if (fs::is_directory(root, ec)) {
    std::vector<fs::path> entries;
    for (const auto& e : fs::directory_iterator(root)) entries.push_back(e.path());
    std::sort(entries.begin(), entries.end());
    for (const fs::path& p : entries) {
      if (fs::is_directory(p) && fs::is_regular_file(p / "grid.csv") && p.filename().string()[0] != '.') {
        BatchPart part{p.filename().string(), (p / "grid.csv").string(), {}};
        if (fs::is_regular_file(p / "options")) part.extra_options = read_options_file(p / "options");
        add(std::move(part), part.input);
      } else if (fs::is_regular_file(p) && is_grid_file_name(p)) {
        add(BatchPart{p.stem().string(), p.string(), {}}, p.string());
      }
    }
    if (parts.empty())
      throw InputError(list_or_folder +
                       ": no grid files here (*.csv, *.txt, *.tsv, *.dat) and no subfolder holding a grid.csv");
  } else if (fs::is_regular_file(root, ec)) {
    std::ifstream in(root);
    if (!in) throw InputError(list_or_folder + ": cannot read");
    const fs::path base = root.parent_path();
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      const std::string entry = trim(line);
      if (entry.empty() || entry[0] == '#') continue;
      const fs::path file = fs::path(entry).is_absolute() ? fs::path(entry) : base / entry;
      const std::string at = list_or_folder + ":" + std::to_string(n);
      if (!fs::is_regular_file(file)) {
        std::string msg = "no such grid file '" + file.string() + "'";
        if (entry.find(',') != std::string::npos)
          msg += " (is " + list_or_folder +
                 " a grid file? gsa batch takes a folder of grid files or a list of them, one path a line)";
        throw InputError(located_message(list_or_folder, n, 0, msg));
      }
      add(BatchPart{part_name_of(file), file.string(), {}}, at);
    }
    if (parts.empty()) throw InputError(list_or_folder + ": the list names no grid file (one path a line)");
  } else {
    throw InputError(list_or_folder + ": no such file or folder; give a folder of grid files or a list of them");
  }
  return parts;
}

std::vector<std::string> parts_in_results(const std::string& dir) {
  std::set<std::string> names;
  const fs::path root(dir);
  if (!fs::is_directory(root)) throw InputError(dir + ": no such folder; give the --out folder of the parts' runs");
  for (const auto& e : fs::directory_iterator(root)) {
    const fs::path p = e.path();
    const std::string name = p.filename().string();
    if (!e.is_directory() || name.empty() || name[0] == '.' || name == kLogsFolder) continue;
    if (name.find(".tmp-") != std::string::npos) continue;  // a run's unfinished temporary folder
    if (fs::exists(p / "summary.json") || fs::exists(p / "strains.csv")) names.insert(name);
  }
  if (fs::is_directory(root / kLogsFolder))
    for (const auto& e : fs::directory_iterator(root / kLogsFolder))
      if (e.is_regular_file() && e.path().extension() == ".log") names.insert(e.path().stem().string());
  return {names.begin(), names.end()};
}

BatchRow collect_part(const std::string& dir, const std::string& part, const std::string& measure) {
  BatchRow row;
  row.part = part;
  const fs::path folder = fs::path(dir) / part;
  const fs::path log = fs::path(dir) / kLogsFolder / (part + ".log");
  if (!fs::is_directory(folder) || !fs::exists(folder / "strains.csv")) {
    row.error = error_from_log(log);
    row.input = input_from_log(log);
    row.status = row.error.empty() ? "missing" : "failed";
    if (row.error.empty()) row.error = "no results folder " + folder.string();
    return row;
  }
  row.results = folder.string();
  try {
    const fs::path summary_path = folder / "summary.json";
    if (fs::exists(summary_path)) {
      const nlohmann::json s = io::read_json(summary_path.string());
      if (s.contains("inputs") && s["inputs"].is_array() && !s["inputs"].empty() && s["inputs"][0].is_string())
        row.input = s["inputs"][0].get<std::string>();
      if (s.contains("timings_s") && s["timings_s"].is_object()) {
        double t = 0;
        for (const auto& [k, v] : s["timings_s"].items())
          if (v.is_number()) t += v.get<double>();
        row.run_time_s = t;
        row.has_time = true;
      }
    }
    const io::CsvTable t = io::read_csv((folder / "strains.csv").string());
    const std::size_t major = t.column_index(major_column(measure));
    const std::size_t thick = t.column_index("thickness_change_pct");
    const auto flc = t.find_column("flc_margin");
    row.points = static_cast<long>(t.n_rows());
    row.analysed = 0;
    double mx = -std::numeric_limits<double>::infinity(), mn = std::numeric_limits<double>::infinity(),
           worst = std::numeric_limits<double>::infinity();
    for (std::size_t r = 0; r < t.n_rows(); ++r) {
      const double e = t.number(r, major, true);
      if (!std::isfinite(e)) continue;
      ++row.analysed;
      mx = std::max(mx, e);
      const double h = t.number(r, thick, true);
      if (std::isfinite(h)) mn = std::min(mn, h);
      if (flc) {
        const double m = t.number(r, *flc, true);
        if (std::isfinite(m)) worst = std::min(worst, m);
      }
    }
    row.has_strains = row.analysed > 0;
    row.max_major = row.has_strains ? mx : kNaN;
    row.min_thickness_change_pct = std::isfinite(mn) ? mn : kNaN;
    row.has_flc = std::isfinite(worst);
    row.worst_flc_margin = row.has_flc ? worst : kNaN;
    row.status = "ok";
  } catch (const Error& e) {
    row.status = "failed";
    row.error = e.what();
  }
  return row;
}

std::string write_batch_table(const std::string& dir, const std::vector<BatchRow>& rows, const std::string& measure) {
  const std::string path = (fs::path(dir) / "batch.csv").string();
  const std::string m = measure_word(measure);
  io::write_file_atomic(path, [&](std::ostream& os) {
    os << "# gsa batch: one row per part; max_major_" << m << " = largest major " << m
       << " strain of the analysed marks, min_thickness_change_pct in percent, worst_flc_margin = smallest "
          "flc_margin (with --flc; < 0 beyond the curve), run_time_s = the part's run time in seconds\n";
    io::CsvWriter w(os, {"part", "status", "input", "points", "points_analysed", "max_major_" + m,
                         "min_thickness_change_pct", "worst_flc_margin", "run_time_s", "results", "error"});
    for (const BatchRow& r : rows) {
      w.begin_row().add(r.part).add(r.status).add(r.input);
      if (r.points >= 0)
        w.add(r.points).add(r.analysed);
      else
        w.add(kNaN).add(kNaN);
      w.add(r.has_strains ? r.max_major : kNaN)
          .add(r.has_strains ? r.min_thickness_change_pct : kNaN)
          .add(r.has_flc ? r.worst_flc_margin : kNaN)
          .add(r.has_time ? std::round(r.run_time_s * 1000) / 1000 : kNaN)
          .add(r.results)
          .add(r.error);
      w.end_row();
    }
  });
  return path;
}

std::string self_executable() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw Error("cannot find this program's path (/proc/self/exe: " + ec.message() + ")");
  return p.string();
}

std::vector<BatchRow> run_batch(const std::string& executable, const std::vector<BatchPart>& parts,
                                const BatchOptions& options,
                                const std::function<void(int, int, const BatchRow&)>& progress) {
  if (options.jobs < 1) throw UsageError("-j: must be >= 1, found " + std::to_string(options.jobs));
  const fs::path out(options.out);
  std::error_code ec;
  fs::create_directories(out / kLogsFolder, ec);
  if (ec) throw Error(options.out + ": cannot create the batch folder (" + ec.message() + ")");

  struct Running {
    std::size_t index;
    std::chrono::steady_clock::time_point start;
  };
  std::map<pid_t, Running> running;
  std::vector<BatchRow> rows(parts.size());
  std::vector<bool> started(parts.size(), false);
  std::string usage_error;
  std::size_t next = 0;
  int done = 0;

  struct sigaction sa {
  }, old_int{}, old_term{};
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  g_interrupted = 0;
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);
  struct Restore {
    struct sigaction a, b;
    ~Restore() {
      sigaction(SIGINT, &a, nullptr);
      sigaction(SIGTERM, &b, nullptr);
    }
  } restore{old_int, old_term};

  auto launch = [&](std::size_t i) {
    const BatchPart& p = parts[i];
    std::vector<std::string> args = {executable, "--quiet", "analyse", p.input, "--out", (out / p.name).string()};
    args.insert(args.end(), options.analyse.begin(), options.analyse.end());
    args.insert(args.end(), p.extra_options.begin(), p.extra_options.end());
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const std::string log = (out / kLogsFolder / (p.name + ".log")).string();
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    {
      std::ofstream header(log, std::ios::trunc);
      header << kLogInputLine << p.input << "\n";
      if (!header) throw Error(log + ": cannot write the part's log");
    }
    posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, executable.c_str(), &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) throw Error(executable + ": cannot start a part's run (" + std::strerror(rc) + ")");
    started[i] = true;
    running.emplace(pid, Running{i, std::chrono::steady_clock::now()});
  };

  while (true) {
    while (!g_interrupted && usage_error.empty() && next < parts.size() &&
           running.size() < static_cast<std::size_t>(options.jobs))
      launch(next++);
    if (running.empty()) break;
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      throw Error(std::string("waiting for the parts' runs: ") + std::strerror(errno));
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const Running r = it->second;
    running.erase(it);
    const BatchPart& p = parts[r.index];
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - r.start).count();
    BatchRow row;
    const fs::path log = out / kLogsFolder / (p.name + ".log");
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
      row = collect_part(options.out, p.name, options.measure);
    } else {
      row.part = p.name;
      row.status = "failed";
      row.error = error_from_log(log);
      if (WIFSIGNALED(status))
        row.error = signal_text(WTERMSIG(status)) + (row.error.empty() ? "" : "; last output: " + row.error);
      if (row.error.empty()) row.error = "exit code " + std::to_string(WEXITSTATUS(status)) + "; see " + log.string();
      if (WIFEXITED(status) && WEXITSTATUS(status) == 2 && usage_error.empty())
        usage_error = row.error.empty() ? "wrong usage" : row.error;
    }
    row.input = p.input;
    row.run_time_s = seconds;
    row.has_time = true;
    rows[r.index] = row;
    ++done;
    if (progress) progress(done, static_cast<int>(parts.size()), rows[r.index]);
  }
  if (!usage_error.empty())
    throw UsageError("gsa analyse rejected the options of the batch (" + usage_error +
                     "); no further parts were started. Check --options (and the parts' options files)");
  if (g_interrupted)
    throw Error("batch interrupted; " + std::to_string(done) + " of " + std::to_string(parts.size()) +
                " parts finished in " + options.out);
  return rows;
}

}  // namespace sf::gsa
