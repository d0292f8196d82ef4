#include "common/render/display.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vtkRenderingOpenGLConfigure.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <sstream>
#include <thread>
#include <vector>

#ifdef __linux__
#include <sys/prctl.h>
#endif

#if defined(VTK_USE_X) && defined(SF_RENDER_HAVE_X11)
#include <X11/Xlib.h>
#endif

#include "common/core/error.hpp"

namespace sf::render {

namespace {

constexpr double kStartTimeoutSeconds = 15.0;
constexpr const char* kWhatToDo =
    "install Xvfb (Debian package 'xvfb'), run under `xvfb-run -a`, set DISPLAY to a "
    "working X server, or skip the pictures (gsa: --no-plots)";

// True when `name` (e.g. ":0", "host:10.0") is an X server that accepts us and has GLX.
bool display_usable(const char* name) {
  if (name == nullptr || *name == '\0') return false;
#if defined(VTK_USE_X) && defined(SF_RENDER_HAVE_X11)
  Display* dpy = XOpenDisplay(name);
  if (dpy == nullptr) return false;
  int opcode = 0, event = 0, error = 0;
  const bool glx = XQueryExtension(dpy, "GLX", &opcode, &event, &error) != 0;
  XCloseDisplay(dpy);
  return glx;
#else
  return true;  // cannot check without Xlib: trust DISPLAY
#endif
}

// Full path of `program` on PATH, or "".
std::string find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return {};
  std::stringstream ss(path);
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    if (dir.empty()) dir = ".";
    const std::string candidate = dir + "/" + program;
    struct stat st {};
    if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(candidate.c_str(), X_OK) == 0)
      return candidate;
  }
  return {};
}

// The last non-empty line of the text in file descriptor `fd` (read from its start).
std::string last_line(int fd) {
  if (fd < 0) return {};
  std::string text;
  char buf[4096];
  if (::lseek(fd, 0, SEEK_SET) < 0) return {};
  ssize_t n = 0;
  while ((n = ::read(fd, buf, sizeof buf)) > 0) text.append(buf, static_cast<std::size_t>(n));
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  const auto nl = text.rfind('\n');
  return nl == std::string::npos ? text : text.substr(nl + 1);
}

void stop_server(pid_t pid) {
  if (pid <= 0) return;
  ::kill(pid, SIGTERM);
  for (int i = 0; i < 200; ++i) {  // up to 2 s
    int status = 0;
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid || (r < 0 && errno == ECHILD)) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
}

struct StartedServer {
  pid_t pid = -1;
  int number = -1;
};

// Starts Xvfb and waits until it accepts connections. Throws sf::Error on failure.
StartedServer start_xvfb(const std::string& xvfb) {
  int fds[2];
  if (::pipe(fds) != 0) throw Error(std::string("cannot draw pictures: pipe() failed: ") + std::strerror(errno));
  // Xvfb's messages go to an anonymous temporary file, read back only to explain a failure.
  char log_name[] = "/tmp/sf-xvfb-log-XXXXXX";
  const int log_fd = ::mkstemp(log_name);
  if (log_fd >= 0) ::unlink(log_name);

  const std::string fd_text = std::to_string(fds[1]);
  std::vector<std::string> args = {xvfb,           "-displayfd", fd_text, "-screen", "0",
                                   "1280x1024x24", "-nolisten",  "tcp",   "-noreset"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int null_fd = ::open("/dev/null", O_RDWR | O_CLOEXEC);

  const pid_t pid = ::fork();
  if (pid < 0) {
    const int err = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    if (log_fd >= 0) ::close(log_fd);
    if (null_fd >= 0) ::close(null_fd);
    throw Error(std::string("cannot draw pictures: fork() failed: ") + std::strerror(err));
  }
  if (pid == 0) {
    // Child: async-signal-safe calls only until exec.
#ifdef __linux__
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);  // do not outlive the process that needs it
#endif
    ::close(fds[0]);
    if (null_fd >= 0) ::dup2(null_fd, STDIN_FILENO);
    if (log_fd >= 0) {
      ::dup2(log_fd, STDOUT_FILENO);
      ::dup2(log_fd, STDERR_FILENO);
    } else if (null_fd >= 0) {
      ::dup2(null_fd, STDOUT_FILENO);
      ::dup2(null_fd, STDERR_FILENO);
    }
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(fds[1]);
  if (null_fd >= 0) ::close(null_fd);

  auto fail = [&](const std::string& why) {
    const std::string tail = last_line(log_fd);
    ::close(fds[0]);
    if (log_fd >= 0) ::close(log_fd);
    stop_server(pid);
    throw Error("cannot draw pictures: no X display (DISPLAY is " +
                std::string(std::getenv("DISPLAY") ? "not usable" : "not set") + ") and " + xvfb + " " + why +
                (tail.empty() ? "" : " (it said: " + tail + ")") + "; " + kWhatToDo);
  };

  // Read the display number Xvfb writes when it is ready ("99\n").
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  std::string number_text;
  while (number_text.find('\n') == std::string::npos) {
    if (elapsed() > kStartTimeoutSeconds) fail("did not start within 15 s");
    pollfd p{fds[0], POLLIN, 0};
    const int r = ::poll(&p, 1, 100);
    if (r < 0 && errno != EINTR) fail("could not be watched");
    if (r > 0) {
      char buf[32];
      const ssize_t n = ::read(fds[0], buf, sizeof buf);
      if (n > 0) {
        number_text.append(buf, static_cast<std::size_t>(n));
      } else if (n == 0) {  // pipe closed: the server exited
        int status = 0;
        ::waitpid(pid, &status, 0);
        const bool not_run = WIFEXITED(status) && WEXITSTATUS(status) == 127;
        fail(not_run ? "could not be run" : "exited before it was ready (status " + std::to_string(status) + ")");
      }
    }
  }
  ::close(fds[0]);
  int number = -1;
  try {
    number = std::stoi(number_text);
  } catch (const std::exception&) {
    fail("reported no display number");
  }
  // Its socket must exist before clients connect.
  const std::string socket = "/tmp/.X11-unix/X" + std::to_string(number);
  for (;;) {
    struct stat st {};
    if (::stat(socket.c_str(), &st) == 0) break;
    if (elapsed() > kStartTimeoutSeconds) fail("created no socket " + socket);
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) fail("exited before it was ready");
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (!display_usable((":" + std::to_string(number)).c_str()))
    fail("started on :" + std::to_string(number) + " but refuses connections or lacks GLX");
  if (log_fd >= 0) ::close(log_fd);
  return {pid, number};
}

}  // namespace

bool renders_without_display() {
#if (defined(VTK_OPENGL_HAS_OSMESA) || defined(VTK_OPENGL_HAS_EGL)) && !defined(VTK_USE_X)
  return true;
#else
  return false;
#endif
}

DisplayGuard::DisplayGuard() {
  if (renders_without_display()) return;
  const char* current = std::getenv("DISPLAY");
  had_display_env_ = current != nullptr;
  if (current) previous_display_ = current;
  if (display_usable(current)) {
    display_ = current;
    return;
  }
  const std::string xvfb = find_on_path("Xvfb");
  if (xvfb.empty())
    throw Error(std::string("cannot draw pictures: no X display (DISPLAY is ") +
                (current ? "'" + previous_display_ + "', which does not accept connections" : std::string("not set")) +
                ") and Xvfb was not found on PATH; " + kWhatToDo);
  const StartedServer s = start_xvfb(xvfb);
  server_pid_ = s.pid;
  display_ = ":" + std::to_string(s.number);
  ::setenv("DISPLAY", display_.c_str(), 1);
}

DisplayGuard::~DisplayGuard() {
  while (!held_.empty()) held_.pop_back();  // windows go before their display
  if (server_pid_ <= 0) return;
  stop_server(server_pid_);
  if (had_display_env_)
    ::setenv("DISPLAY", previous_display_.c_str(), 1);
  else
    ::unsetenv("DISPLAY");
}

std::shared_ptr<DisplayGuard> acquire_display() {
  static std::mutex mutex;
  static std::weak_ptr<DisplayGuard> current;
  const std::lock_guard<std::mutex> lock(mutex);
  if (auto alive = current.lock()) return alive;
  auto guard = std::make_shared<DisplayGuard>();
  current = guard;
  return guard;
}

}  // namespace sf::render
