// The options dictionary of the D-Bus Calibrate call, as the daemon reads it once sd-bus has checked the
// call's signature (sa{sv}). The input is a list of entries, each a key selector byte (one of the known keys,
// or the following NUL-terminated bytes as a key), a type selector byte and the value's bytes; they are
// appended to a real sd-bus message, which is then read. Bad options may only give BusError.
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <string>

#include <systemd/sd-bus.h>

#include "service/bus_error.h"
#include "service/bus_names.h"
#include "service/calibrate_options.h"

namespace {

using namespace everytouch;

class Input {
public:
    Input(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
    bool empty() const { return at_ >= size_; }
    std::uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
    template <typename T>
    T value() {
        T v{};
        const std::size_t n = std::min(sizeof v, size_ - std::min(at_, size_));
        std::memcpy(&v, data_ + at_, n);
        at_ += n;
        return v;
    }
    std::string text() {
        std::string s;
        while (at_ < size_ && data_[at_] != 0)
            s.push_back(static_cast<char>(data_[at_++]));
        ++at_;
        return s;
    }

private:
    const std::uint8_t* data_;
    std::size_t size_;
    std::size_t at_ = 0;
};

// A bus on one end of a socket pair: enough for sd-bus to build messages; nothing is ever sent.
sd_bus* messageFactory() {
    static sd_bus* bus = [] {
        int fds[2];
        sd_bus* b = nullptr;
        if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) < 0 || sd_bus_new(&b) < 0 ||
            sd_bus_set_fd(b, fds[0], fds[0]) < 0 || sd_bus_start(b) < 0)
            __builtin_trap();
        return b;
    }();
    return bus;
}

// Appends one variant of the type the selector names, its value from the input.
int appendVariant(sd_bus_message* m, Input& in) {
    switch (in.byte() % 7) {
        case 0:
            return sd_bus_message_append(m, "v", "u", in.value<std::uint32_t>());
        case 1:
            return sd_bus_message_append(m, "v", "d", in.value<double>());
        case 2:
            return sd_bus_message_append(m, "v", "i", in.value<std::int32_t>());
        case 3:
            return sd_bus_message_append(m, "v", "s", in.text().c_str());
        case 4:
            return sd_bus_message_append(m, "v", "b", static_cast<int>(in.byte() & 1));
        case 5:
            return sd_bus_message_append(m, "v", "t", in.value<std::uint64_t>());
        default:
            return sd_bus_message_append(m, "v", "as", 2, in.text().c_str(), in.text().c_str());
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const char* const kKeys[] = {bus::kOptionFrames, bus::kOptionCardWidthMm, bus::kOptionCardHeightMm,
                                        bus::kOptionViews, bus::kOptionViewTimeoutS};
    Input in(data, size);
    sd_bus_message* m = nullptr;
    if (sd_bus_message_new_method_call(messageFactory(), &m, bus::kBusName, bus::kObjectPath, bus::kInterface,
                                       bus::kMethodCalibrate) < 0)
        __builtin_trap();
    bool built = sd_bus_message_open_container(m, 'a', "{sv}") >= 0;
    while (built && !in.empty()) {
        const std::uint8_t selector = in.byte();
        const std::string key = selector < 250 ? kKeys[selector % 5] : in.text();
        built = sd_bus_message_open_container(m, 'e', "sv") >= 0 &&
                sd_bus_message_append(m, "s", key.c_str()) >= 0 && appendVariant(m, in) >= 0 &&
                sd_bus_message_close_container(m) >= 0;
    }
    // sd-bus refuses what is not valid D-Bus (a key that is not UTF-8): no client can send it.
    if (built && sd_bus_message_close_container(m) >= 0 && sd_bus_message_seal(m, 1, 0) >= 0 &&
        sd_bus_message_rewind(m, true) >= 0) {
        try {
            (void)service::readCalibrationOptions(m);
        } catch (const service::BusError&) {
        }
    }
    sd_bus_message_unref(m);
    return 0;
}
