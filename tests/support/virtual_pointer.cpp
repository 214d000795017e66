#include "support/virtual_pointer.h"

#include <linux/input-event-codes.h>

#include <cstring>
#include <stdexcept>

#include "io/wayland_handles.h"
#include "wlr-virtual-pointer-unstable-v1-client-protocol.h"

namespace everytouch::test {

// Named, not anonymous: the connection's handle types of the class below use them.
namespace virtual_pointer_protocol {

void destroyPointer(zwlr_virtual_pointer_v1* pointer) {
    zwlr_virtual_pointer_v1_destroy(pointer);
}
void destroyManager(zwlr_virtual_pointer_manager_v1* manager) {
    zwlr_virtual_pointer_manager_v1_destroy(manager);
}

struct Globals {
    wl_seat* seat = nullptr;
    zwlr_virtual_pointer_manager_v1* manager = nullptr;
};

void announceGlobal(void* data, wl_registry* registry, std::uint32_t name, const char* interface,
                    std::uint32_t /*version*/) {
    auto* globals = static_cast<Globals*>(data);
    if (std::strcmp(interface, wl_seat_interface.name) == 0 && !globals->seat)
        globals->seat = static_cast<wl_seat*>(wl_registry_bind(registry, name, &wl_seat_interface, 1));
    else if (std::strcmp(interface, zwlr_virtual_pointer_manager_v1_interface.name) == 0)
        globals->manager = static_cast<zwlr_virtual_pointer_manager_v1*>(
            wl_registry_bind(registry, name, &zwlr_virtual_pointer_manager_v1_interface, 1));
}

void removeGlobal(void*, wl_registry*, std::uint32_t) {}

constexpr wl_registry_listener kRegistryListener{announceGlobal, removeGlobal};

}  // namespace virtual_pointer_protocol

using namespace virtual_pointer_protocol;

// The connection first: its objects go before it.
struct VirtualPointer::Connection {
    io::WaylandDisplay display;
    io::WaylandRegistry registry;
    io::UniqueHandle<wl_seat, io::wayland::forget<wl_seat>> seat;
    io::UniqueHandle<zwlr_virtual_pointer_manager_v1, destroyManager> manager;
    io::UniqueHandle<zwlr_virtual_pointer_v1, destroyPointer> pointer;
};

VirtualPointer::VirtualPointer(const std::string& socket) : connection_(std::make_unique<Connection>()) {
    Connection& c = *connection_;
    c.display.reset(wl_display_connect(socket.c_str()));
    if (!c.display)
        throw std::runtime_error("cannot connect to the Wayland compositor at " + socket);
    c.registry.reset(wl_display_get_registry(c.display.get()));
    Globals globals;
    wl_registry_add_listener(c.registry.get(), &kRegistryListener, &globals);
    wl_display_roundtrip(c.display.get());
    c.seat.reset(globals.seat);
    c.manager.reset(globals.manager);
    if (!c.manager)
        throw std::runtime_error("the compositor at " + socket + " offers no virtual pointer");
    c.pointer.reset(zwlr_virtual_pointer_manager_v1_create_virtual_pointer(c.manager.get(), c.seat.get()));
    wl_display_roundtrip(c.display.get());
}

VirtualPointer::~VirtualPointer() = default;

void VirtualPointer::moveTo(int x, int y, int width, int height) {
    zwlr_virtual_pointer_v1_motion_absolute(connection_->pointer.get(), nextTimeMs(), x, y, width, height);
    zwlr_virtual_pointer_v1_frame(connection_->pointer.get());
    roundTrip();
}

void VirtualPointer::click() {
    zwlr_virtual_pointer_v1* pointer = connection_->pointer.get();
    zwlr_virtual_pointer_v1_button(pointer, nextTimeMs(), BTN_LEFT, WL_POINTER_BUTTON_STATE_PRESSED);
    zwlr_virtual_pointer_v1_frame(pointer);
    zwlr_virtual_pointer_v1_button(pointer, nextTimeMs(), BTN_LEFT, WL_POINTER_BUTTON_STATE_RELEASED);
    zwlr_virtual_pointer_v1_frame(pointer);
    roundTrip();
}

std::uint32_t VirtualPointer::nextTimeMs() {
    return ++timeMs_;
}

void VirtualPointer::roundTrip() {
    if (wl_display_roundtrip(connection_->display.get()) < 0)
        throw std::runtime_error("the Wayland compositor closed the virtual pointer's connection");
}

}  // namespace everytouch::test
