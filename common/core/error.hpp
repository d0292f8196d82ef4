#pragma once
// Error channels (STYLE.md):
//  1. programmer mistakes  -> SF_ASSERT (debug builds only);
//  2. bad input from outside -> sf::InputError (always on; names file/line/column/option);
//  3. numerical outcomes    -> a report struct with a status, returned to the caller.

#include <stdexcept>
#include <string>

namespace sf {

// Base of every error the suite throws for bad input from outside (files, options, cases).
// Executables catch it at the top, print what() on one line and exit with code 1.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Bad input: message already names where (file:line:column or --option) and what was expected.
class InputError : public Error {
 public:
  using Error::Error;
};

// Wrong usage of a command line (exit code 2).
class UsageError : public Error {
 public:
  using Error::Error;
};

// Formats "file:line:column: message" (line/column 1-based; 0 = not applicable).
std::string located_message(const std::string& file, int line, int column, const std::string& message);

namespace detail {
[[noreturn]] void assert_fail(const char* expr, const char* file, int line, const std::string& msg);
}  // namespace detail

}  // namespace sf

#ifdef NDEBUG
#define SF_ASSERT(cond, msg) ((void)0)
#else
#define SF_ASSERT(cond, msg) ((cond) ? (void)0 : ::sf::detail::assert_fail(#cond, __FILE__, __LINE__, (msg)))
#endif
