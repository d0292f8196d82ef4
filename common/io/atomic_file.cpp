#include "common/io/atomic_file.hpp"

#include <fmt/format.h>
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

std::string temp_suffix() { return fmt::format(".tmp-{}-{}", static_cast<long>(::getpid()), g_temp_counter++); }

[[noreturn]] void throw_fs_error(const fs::path& path, const std::string& what, const std::error_code& ec) {
  throw Error(located_message(path.string(), 0, 0, fmt::format("{} ({})", what, ec.message())));
}

// Moves file `from` onto `to` (replacing it). Falls back to copy + rename when the two are on
// different file systems.
void move_file(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (!ec) return;
  const fs::path staging = fs::path(to.string() + temp_suffix());
  std::error_code copy_ec;
  fs::copy_file(from, staging, fs::copy_options::overwrite_existing, copy_ec);
  if (!copy_ec) fs::rename(staging, to, copy_ec);
  if (copy_ec) {
    std::error_code ignored;
    fs::remove(staging, ignored);
    throw_fs_error(to, "cannot move the output file into place", ec);
  }
  fs::remove(from, ec);
}

}  // namespace

AtomicOutputDir::AtomicOutputDir(const fs::path& final_dir) {
  fs::path dir = final_dir.empty() ? fs::path(".") : final_dir;
  dir = fs::absolute(dir).lexically_normal();
  if (!dir.has_filename()) dir = dir.parent_path();  // "out/" -> "out"
  final_dir_ = dir;
  temp_dir_ = fs::path(dir.string() + temp_suffix());
  std::error_code ec;
  fs::remove_all(temp_dir_, ec);  // a stale one from a killed process with the same pid
  fs::create_directories(temp_dir_, ec);
  if (ec) throw_fs_error(temp_dir_, "cannot create the temporary output directory", ec);
}

AtomicOutputDir::~AtomicOutputDir() {
  std::error_code ec;
  fs::remove_all(temp_dir_, ec);  // nothing left after commit(); everything when abandoned
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

void AtomicOutputDir::commit() {
  if (committed_) throw std::logic_error("AtomicOutputDir::commit() called twice");
  std::error_code ec;
  if (!fs::exists(final_dir_, ec)) {
    fs::rename(temp_dir_, final_dir_, ec);
    if (!ec) {
      committed_ = true;
      return;
    }
  }
  if (fs::exists(final_dir_, ec) && !fs::is_directory(final_dir_, ec)) {
    throw Error(
        located_message(final_dir_.string(), 0, 0, "cannot write the output: it exists and is not a directory"));
  }
  fs::create_directories(final_dir_, ec);
  if (ec) throw_fs_error(final_dir_, "cannot create the output directory", ec);
  // List first, then move: a directory changed while iterating may be listed incompletely.
  std::vector<fs::path> entries;
  for (auto it = fs::recursive_directory_iterator(temp_dir_, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    entries.push_back(it->path());
  }
  if (ec) throw_fs_error(temp_dir_, "cannot list the temporary output directory", ec);
  for (const fs::path& entry : entries) {
    const fs::path target = final_dir_ / entry.lexically_relative(temp_dir_);
    if (fs::is_directory(entry, ec)) {
      fs::create_directories(target, ec);
      if (ec) throw_fs_error(target, "cannot create directory", ec);
    } else {
      move_file(entry, target);
    }
  }
  committed_ = true;
  fs::remove_all(temp_dir_, ec);
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
