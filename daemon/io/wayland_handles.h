#pragma once

#include <wayland-client.h>

#include "io/handles.h"
#include "wlr-layer-shell-unstable-v1-client-protocol.h"

namespace everytouch::io {

// libwayland's destructors are static inline functions of its headers, which a handle type that other
// files may see must not name: these forward to them.
namespace wayland {
inline void disconnect(wl_display* display) {
    wl_display_disconnect(display);
}
// Globals and callbacks have no destructor request in the versions the overlay binds: only the client's
// proxy goes (closing the connection frees the rest on the compositor's side).
template <typename Proxy>
void forget(Proxy* proxy) {
    wl_proxy_destroy(reinterpret_cast<wl_proxy*>(proxy));
}
inline void destroySurface(wl_surface* surface) {
    wl_surface_destroy(surface);
}
inline void destroyBuffer(wl_buffer* buffer) {
    wl_buffer_destroy(buffer);
}
inline void destroyLayerSurface(zwlr_layer_surface_v1* surface) {
    zwlr_layer_surface_v1_destroy(surface);
}
}  // namespace wayland

// A Wayland compositor connection and the objects made on it. Objects go before the connection: declare
// the connection first.
using WaylandDisplay = UniqueHandle<wl_display, wayland::disconnect>;
using WaylandRegistry = UniqueHandle<wl_registry, wayland::forget<wl_registry>>;
using WaylandCompositor = UniqueHandle<wl_compositor, wayland::forget<wl_compositor>>;
using WaylandShm = UniqueHandle<wl_shm, wayland::forget<wl_shm>>;
using WaylandOutput = UniqueHandle<wl_output, wayland::forget<wl_output>>;
using WaylandCallback = UniqueHandle<wl_callback, wayland::forget<wl_callback>>;
using LayerShell = UniqueHandle<zwlr_layer_shell_v1, wayland::forget<zwlr_layer_shell_v1>>;
using WaylandSurface = UniqueHandle<wl_surface, wayland::destroySurface>;
using WaylandBuffer = UniqueHandle<wl_buffer, wayland::destroyBuffer>;
using LayerSurface = UniqueHandle<zwlr_layer_surface_v1, wayland::destroyLayerSurface>;

}  // namespace everytouch::io
