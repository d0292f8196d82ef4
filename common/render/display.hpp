#pragma once
// A display for off-screen rendering on machines without one (servers, CI).
//
// Debian's VTK 9.1 renders through X/GLX only: without a reachable X server VTK prints
// "bad X server connection" and calls abort(). So every render first holds a DisplayGuard:
//
//  1. a VTK built with OSMesa or EGL and without X needs no display: the guard does nothing;
//  2. else, if DISPLAY names a server that accepts a connection and offers GLX, it is used;
//  3. else a private `Xvfb -displayfd FD -screen 0 1280x1024x24 -nolisten tcp` is started on
//     a free display number (Xvfb picks it), the guard waits until its socket
//     /tmp/.X11-unix/X<N> exists, sets DISPLAY=:<N> for this process, and on destruction
//     stops the server and restores DISPLAY;
//  4. if Xvfb is not on PATH or does not come up, the constructor throws sf::Error saying so
//     (and what to do); VTK is never reached.
//
// Guards may nest; render::write_png() acquires the shared one itself. Hold a guard across
// several renders (acquire_display()) to start Xvfb only once; the renderer in this folder
// then also reuses one window for all of them (held by the guard, see hold()). Destroy every
// render window before the guard that gave it its display.

#include <memory>
#include <string>
#include <utility>
#include <vector>
#include <sys/types.h>

namespace sf::render {

class DisplayGuard {
 public:
  // Finds or starts a display; throws sf::Error when none can be had.
  DisplayGuard();
  ~DisplayGuard();
  DisplayGuard(const DisplayGuard&) = delete;
  DisplayGuard& operator=(const DisplayGuard&) = delete;

  // The X display in use (":99"), or "" when rendering needs none.
  const std::string& display() const { return display_; }
  // True when this guard started (and will stop) a private Xvfb.
  bool owns_server() const { return server_pid_ > 0; }

  // Keeps `resource` (e.g. a render window reused across pictures) alive as long as this
  // guard, and destroys it first in the guard's destructor, while the display still exists.
  void hold(std::shared_ptr<void> resource) { held_.push_back(std::move(resource)); }

 private:
  std::string display_;
  pid_t server_pid_ = -1;
  bool had_display_env_ = false;
  std::string previous_display_;
  std::vector<std::shared_ptr<void>> held_;
};

// The process-wide guard: the one alive if any, else a new one. It lives while a caller
// holds the pointer. Thread-safe.
std::shared_ptr<DisplayGuard> acquire_display();

// True when VTK was built to render without any display (OSMesa or EGL, no X).
bool renders_without_display();

}  // namespace sf::render
