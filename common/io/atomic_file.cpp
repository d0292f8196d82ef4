#include "common/io/atomic_file.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <fnmatch.h>
#include <signal.h>
#include <stdio.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "common/core/error.hpp"

namespace sf::io {

namespace fs = std::filesystem;

namespace {

std::atomic<unsigned> g_temp_counter{0};

std::string temp_suffix(const char* kind = ".tmp-") {
  return fmt::format("{}{}-{}", kind, static_cast<long>(::getpid()), g_temp_counter++);
}

[[noreturn]] void throw_fs_error(const fs::path& path, const std::string& what, const std::error_code& ec) {
  throw Error(located_message(path.string(), 0, 0, fmt::format("{} ({})", what, ec.message())));
}

[[noreturn]] void throw_errno(const fs::path& path, const std::string& what) {
  throw_fs_error(path, what, std::error_code(errno, std::generic_category()));
}

// ".NAME.lock" beside the folder NAME.
fs::path lock_path(const fs::path& dir) { return dir.parent_path() / ("." + dir.filename().string() + ".lock"); }

bool process_running(long pid) {
  if (pid <= 0) return false;
  if (::kill(static_cast<pid_t>(pid), 0) == 0) return true;
  return errno == EPERM;  // exists, owned by someone else
}

// PID of a sibling "NAME<kind>PID-N" of `name`, or -1 when `entry` is not one.
long temp_owner(const std::string& entry, const std::string& name, const std::string& kind) {
  const std::string prefix = name + kind;
  if (entry.size() <= prefix.size() || entry.compare(0, prefix.size(), prefix) != 0) return -1;
  const std::string rest = entry.substr(prefix.size());
  const std::size_t dash = rest.find('-');
  if (dash == 0 || dash == std::string::npos || dash + 1 == rest.size()) return -1;
  for (std::size_t i = 0; i < rest.size(); ++i)
    if (i != dash && (rest[i] < '0' || rest[i] > '9')) return -1;
  if (dash > 9) return -1;
  return std::stol(rest.substr(0, dash));
}

// Hard-links `from` (a file, symlink or directory tree) to `to` where `to` does not exist
// yet; directories present on both sides are merged; existing files at `to` win.
void link_tree(const fs::path& from, const fs::path& to, const std::vector<std::string>* owned_top = nullptr) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(from, ec);
  if (ec) throw_fs_error(from, "cannot read", ec);
  const fs::file_status st_to = fs::symlink_status(to, ec);
  const bool to_exists = fs::exists(st_to);
  if (fs::is_directory(st)) {
    if (to_exists && !fs::is_directory(st_to)) return;  // the new output wins
    if (!to_exists) {
      fs::create_directory(to, ec);
      if (ec) throw_fs_error(to, "cannot create directory", ec);
    }
    std::vector<fs::path> entries;
    for (auto it = fs::directory_iterator(from, ec); !ec && it != fs::directory_iterator(); it.increment(ec))
      entries.push_back(it->path());
    if (ec) throw_fs_error(from, "cannot list", ec);
    for (const fs::path& e : entries) {
      const std::string name = e.filename().string();
      if (owned_top) {
        bool owned = false;
        for (const std::string& pattern : *owned_top)
          if (::fnmatch(pattern.c_str(), name.c_str(), FNM_PERIOD) == 0) owned = true;
        if (owned) continue;
      }
      link_tree(e, to / name);
    }
    return;
  }
  if (to_exists) return;
  if (fs::is_symlink(st)) {
    fs::copy_symlink(from, to, ec);
    if (ec) throw_fs_error(to, "cannot copy link", ec);
    return;
  }
  if (::link(from.c_str(), to.c_str()) == 0) return;
  fs::copy_file(from, to, ec);  // no hard links on this file system
  if (ec) throw_fs_error(to, "cannot copy the earlier file into the new output", ec);
}

}  // namespace

int clean_stale_temporaries(const fs::path& final_dir) {
  const fs::path parent = final_dir.parent_path();
  const std::string name = final_dir.filename().string();
  std::error_code ec;
  std::vector<fs::path> stale_tmp, stale_old;
  for (auto it = fs::directory_iterator(parent, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    const long tmp_pid = temp_owner(entry, name, ".tmp-");
    const long old_pid = temp_owner(entry, name, ".old-");
    if (tmp_pid > 0 && !process_running(tmp_pid)) stale_tmp.push_back(it->path());
    if (old_pid > 0 && !process_running(old_pid)) stale_old.push_back(it->path());
  }
  int removed = 0;
  // Killed between "old aside" and "new in": the old folder is the last complete one.
  if (!fs::exists(fs::symlink_status(final_dir, ec)) && !stale_old.empty()) {
    fs::rename(stale_old.back(), final_dir, ec);
    if (!ec) stale_old.pop_back();
  }
  for (const auto* list : {&stale_tmp, &stale_old})
    for (const fs::path& p : *list) {
      fs::remove_all(p, ec);
      if (!ec) ++removed;
    }
  return removed;
}

AtomicOutputDir::AtomicOutputDir(const fs::path& final_dir, const OutputDirOptions& options) : options_(options) {
  if (final_dir.empty()) throw Error("output folder: the name is empty; give a folder to write the results into");
  fs::path dir = fs::absolute(final_dir).lexically_normal();
  if (!dir.has_filename()) dir = dir.parent_path();  // "out/" -> "out"
  if (dir == dir.root_path() || dir.filename() == "..")
    throw Error(located_message(final_dir.string(), 0, 0, "cannot write results into this folder; name a folder"));
  std::error_code ec;
  // The current folder or one above it cannot be swapped: the shell would be left in a
  // removed folder.
  const fs::path cwd = fs::current_path(ec).lexically_normal();
  if (!ec) {
    const auto rel = cwd.lexically_relative(dir);
    if (!rel.empty() && *rel.begin() != "..")
      throw Error(located_message(final_dir.string(), 0, 0,
                                  "is the current folder or contains it; write the results into a folder below it "
                                  "(e.g. --out results)"));
  }
  final_dir_ = dir;
  fs::create_directories(dir.parent_path(), ec);
  if (ec) throw_fs_error(dir.parent_path(), "cannot create the folder", ec);

  // The lock: one run per output folder at a time. An flock() belongs to the open file and
  // the kernel drops it when its process ends, however it ends: the lock file a killed run
  // leaves behind is never locked, so it cannot block the next run (which takes it over and
  // removes it when it ends). The run holding the lock removes the file before it lets go;
  // a run that opened the file just before that removal would hold a lock on a file that is
  // gone, so after locking it checks that the path still names the file it locked.
  const fs::path lock = lock_path(dir);
  for (int attempt = 0;; ++attempt) {
    lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (lock_fd_ < 0) throw_errno(lock, "cannot create the lock file of the output folder");
    if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      char buf[32] = {0};
      const ssize_t n = ::pread(lock_fd_, buf, sizeof buf - 1, 0);
      std::string holder = n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string("?");
      while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
      ::close(lock_fd_);
      lock_fd_ = -1;
      if (err == EWOULDBLOCK)
        throw Error(located_message(final_dir_.string(), 0, 0,
                                    "another run (process " + holder +
                                        ") is writing this folder now; wait for it to finish or choose another "
                                        "output folder"));
      errno = err;
      throw_errno(lock, "cannot lock the output folder");
    }
    struct stat held {
    }, named{};
    if (::fstat(lock_fd_, &held) == 0 && ::stat(lock.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
        held.st_ino == named.st_ino)
      break;
    ::close(lock_fd_);  // removed by the run that held it: lock the file that is there now
    lock_fd_ = -1;
    if (attempt == 100)
      throw Error(located_message(lock.string(), 0, 0, "cannot lock the output folder (the lock file keeps changing)"));
  }
  const std::string me = std::to_string(static_cast<long>(::getpid())) + "\n";
  if (::ftruncate(lock_fd_, 0) == 0) {
    [[maybe_unused]] const ssize_t w = ::pwrite(lock_fd_, me.data(), me.size(), 0);
  }

  clean_stale_temporaries(final_dir_);

  if (options_.work_suffix.empty()) {
    temp_dir_ = fs::path(dir.string() + temp_suffix());
    fs::remove_all(temp_dir_, ec);
  } else {
    temp_dir_ = fs::path(dir.string() + options_.work_suffix);
    if (!options_.resume) fs::remove_all(temp_dir_, ec);
  }
  fs::create_directories(temp_dir_, ec);
  if (ec) {
    ::unlink(lock.c_str());
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw_fs_error(temp_dir_, "cannot create the temporary output directory", ec);
  }
}

AtomicOutputDir::~AtomicOutputDir() {
  std::error_code ec;
  // Nothing left after commit(); everything when abandoned (but a working folder stays).
  if (committed_ || options_.work_suffix.empty()) fs::remove_all(temp_dir_, ec);
  if (lock_fd_ >= 0) {
    ::unlink(lock_path(final_dir_).c_str());  // still held: no other run can have locked this file
    ::close(lock_fd_);                        // releases the lock
  }
}

std::string AtomicOutputDir::path(const std::string& name) const {
  if (committed_) throw std::logic_error("AtomicOutputDir::path() after commit(): " + name);
  const fs::path rel = fs::path(name).lexically_normal();
  if (name.empty() || rel.is_absolute() || !rel.has_filename() || *rel.begin() == "..") {
    throw std::logic_error("AtomicOutputDir::path(): not a relative file name: '" + name + "'");
  }
  const fs::path full = temp_dir_ / rel;
  if (rel.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(full.parent_path(), ec);
    if (ec) throw_fs_error(full.parent_path(), "cannot create directory", ec);
  }
  return full.string();
}

bool AtomicOutputDir::seed_from_final() {
  if (committed_) throw std::logic_error("AtomicOutputDir::seed_from_final() after commit()");
  std::error_code ec;
  if (!fs::is_directory(final_dir_, ec)) return false;
  link_tree(final_dir_, temp_dir_);
  return true;
}

void AtomicOutputDir::commit() {
  if (committed_) throw std::logic_error("AtomicOutputDir::commit() called twice");
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(final_dir_, ec);
  if (!fs::exists(st)) {
    fs::rename(temp_dir_, final_dir_, ec);
    if (ec) throw_fs_error(final_dir_, "cannot move the output folder into place", ec);
    committed_ = true;
    return;
  }
  if (!fs::is_directory(st)) {
    throw Error(located_message(final_dir_.string(), 0, 0,
                                "cannot write the output: it exists and is not a directory (or is a link)"));
  }
  // The old folder's other files (not outputs of this command) come along.
  link_tree(final_dir_, temp_dir_, &options_.owned);
  // One step: exchange the two folders, then remove the old one.
  if (::renameat2(AT_FDCWD, temp_dir_.c_str(), AT_FDCWD, final_dir_.c_str(), RENAME_EXCHANGE) == 0) {
    committed_ = true;
    fs::remove_all(temp_dir_, ec);
    return;
  }
  if (errno != EINVAL && errno != ENOSYS && errno != ENOTSUP && errno != EPERM)
    throw_errno(final_dir_, "cannot replace the output folder");
  // No exchange on this file system: old aside, new in, old removed.
  const fs::path old = fs::path(final_dir_.string() + temp_suffix(".old-"));
  fs::rename(final_dir_, old, ec);
  if (ec) throw_fs_error(final_dir_, "cannot move the earlier output folder aside", ec);
  fs::rename(temp_dir_, final_dir_, ec);
  if (ec) {
    std::error_code ignored;
    fs::rename(old, final_dir_, ignored);
    throw_fs_error(final_dir_, "cannot move the output folder into place", ec);
  }
  committed_ = true;
  fs::remove_all(old, ec);
}

void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const std::string tmp = path + fmt::format(".tmp-{}", static_cast<long>(::getpid()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw Error(located_message(path, 0, 0, fmt::format("cannot write file ({})", std::strerror(errno))));
    }
    try {
      write(out);
    } catch (...) {
      out.close();
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw;
    }
    out.flush();
    out.close();
    if (!out) {
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw Error(located_message(path, 0, 0, "cannot write file (write failed; disk full?)"));
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw_fs_error(path, "cannot write file", ec);
  }
}

void write_file_atomic(const std::string& path, const std::string& content) {
  write_file_atomic(
      path, [&content](std::ostream& out) { out.write(content.data(), static_cast<std::streamsize>(content.size())); });
}

}  // namespace sf::io
