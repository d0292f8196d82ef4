#pragma once
// Shared command-line layer: git-style subcommands on CLI11, --help, --version,
// the exit codes of CONTRACT.md and one clean error line on stderr.
//
//   0  success
//   1  bad input or a run that could not converge (message names file/line/column or step)
//   2  wrong usage (unknown option, missing argument)

#include <functional>
#include <memory>
#include <string>

namespace CLI {
class App;
}

namespace sf::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;

// The command line of this run as typed (arguments with spaces or quotes quoted), for
// the record in output files; empty before Program::main.
const std::string& command_line();

// `message` cut to about `limit` characters (its start and end kept, the middle replaced by
// "[... N characters left out ...]"): a 30 MB header line is never echoed whole.
std::string shortened_message(const std::string& message, std::size_t limit = 600);

// Options every subcommand understands.
struct CommonOptions {
  bool quiet = false;  // --quiet: no progress on stderr
};

class Program {
 public:
  Program(std::string name, std::string description);
  ~Program();
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  // Adds a subcommand; `configure` declares its options on the CLI11 app, `run`
  // executes it after parsing and returns an exit code.
  void add_command(const std::string& name, const std::string& description,
                   const std::function<void(CLI::App&)>& configure, const std::function<int()>& run);

  // Parses, dispatches, catches every error at the top and maps it to an exit code.
  int main(int argc, char** argv);

  const CommonOptions& common() const { return common_; }

 private:
  std::string name_;
  std::unique_ptr<CLI::App> app_;
  CommonOptions common_;
  struct Command;
  std::vector<std::unique_ptr<Command>> commands_;
};

}  // namespace sf::cli
