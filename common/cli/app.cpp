#include "common/cli/app.hpp"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <iostream>
#include <new>
#include <vector>

#include "common/core/error.hpp"

namespace sf::cli {

namespace {
std::string& recorded_command_line() {
  static std::string line;
  return line;
}

std::string quoted_argument(const std::string& a) {
  if (!a.empty() && a.find_first_of(" \t'\"\\$`") == std::string::npos) return a;
  std::string q = "'";
  for (char c : a) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}
}  // namespace

const std::string& command_line() { return recorded_command_line(); }

struct Program::Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Program::Program(std::string name, std::string description)
    : name_(std::move(name)), app_(std::make_unique<CLI::App>(std::move(description), name_)) {
  app_->set_version_flag("--version", std::string(name_) + " " + SF_VERSION);
  app_->require_subcommand(1);
  app_->fallthrough();
  app_->add_flag("-q,--quiet", common_.quiet, "No progress messages on stderr");
}

Program::~Program() = default;

void Program::add_command(const std::string& name, const std::string& description,
                          const std::function<void(CLI::App&)>& configure, const std::function<int()>& run) {
  auto cmd = std::make_unique<Command>();
  cmd->app = app_->add_subcommand(name, description);
  configure(*cmd->app);
  cmd->run = run;
  commands_.push_back(std::move(cmd));
}

std::string shortened_message(const std::string& message, std::size_t limit) {
  if (message.size() <= limit) return message;
  // Keep the start (file, line, column, what went wrong) and the end (what was expected).
  const std::size_t head = limit * 2 / 3, tail = limit / 3;
  return message.substr(0, head) + " [... " + std::to_string(message.size() - head - tail) +
         " characters left out ...] " + message.substr(message.size() - tail);
}

int Program::main(int argc, char** argv) {
  std::string line = name_;
  for (int i = 1; i < argc; ++i) line += " " + quoted_argument(argv[i]);
  recorded_command_line() = line;
  try {
    app_->parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app_->exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app_->exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app_->exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << name_ << ": " << shortened_message(e.what()) << "\n"
              << "Run '" << name_ << " --help' for usage.\n";
    return kExitUsage;
  }
  for (const auto& cmd : commands_) {
    if (!cmd->app->parsed()) continue;
    try {
      return cmd->run();
    } catch (const UsageError& e) {
      std::cerr << name_ << ": " << shortened_message(e.what()) << "\n";
      return kExitUsage;
    } catch (const Error& e) {
      std::cerr << name_ << ": error: " << shortened_message(e.what()) << "\n";
      return kExitFailure;
    } catch (const std::bad_alloc&) {
      std::cerr << name_ << ": error: out of memory\n";
      return kExitFailure;
    } catch (const std::exception& e) {
      std::cerr << name_ << ": internal error: " << shortened_message(e.what())
                << " (please report this with the input that caused it)\n";
      return kExitFailure;
    }
  }
  std::cerr << name_ << ": no command given; run '" << name_ << " --help'\n";
  return kExitUsage;
}

}  // namespace sf::cli
