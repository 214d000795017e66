#pragma once

#include <cstdint>
#include <memory>
#include <string>

namespace everytouch::test {

// A mouse on a Wayland compositor that offers the virtual pointer protocol (zwlr_virtual_pointer_v1, as
// sway does): the compositor's seat gets a pointer as a real one would, so clients receive its motion and
// clicks wherever their input regions take them. A headless compositor has no input device of its own.
class VirtualPointer {
public:
    // Connects to the compositor at `socket` (WAYLAND_DISPLAY's value). Throws std::runtime_error when it
    // cannot, or when the compositor lacks the protocol.
    explicit VirtualPointer(const std::string& socket);
    ~VirtualPointer();
    VirtualPointer(const VirtualPointer&) = delete;
    VirtualPointer& operator=(const VirtualPointer&) = delete;

    // Moves to (x, y) of the output, whose size is `width` x `height` pixels. Returns once the compositor
    // has handled it.
    void moveTo(int x, int y, int width, int height);
    // Presses the left button and releases it where the pointer is. Returns once the compositor has handled
    // both.
    void click();

private:
    struct Connection;
    // Event times, milliseconds: they only need to increase.
    std::uint32_t nextTimeMs();
    void roundTrip();

    std::unique_ptr<Connection> connection_;
    std::uint32_t timeMs_ = 0;
};

}  // namespace everytouch::test
