#include "service/calibrate_options.h"

#include <cstdint>
#include <cstring>
#include <string>

#include "service/bus_error.h"
#include "service/bus_names.h"

namespace everytouch::service {

namespace {

template <typename T>
T readOption(sd_bus_message* message, const char* key, const char* type) {
    const char* contents = nullptr;
    checkBusCall(sd_bus_message_peek_type(message, nullptr, &contents), "Calibrate options");
    if (!contents || std::strcmp(contents, type) != 0)
        throw BusError(SD_BUS_ERROR_INVALID_ARGS, std::string("Calibrate option \"") + key +
                                                      "\" must be of type " + type + ", not " +
                                                      (contents ? contents : "?"));
    T value{};
    checkBusCall(sd_bus_message_read(message, "v", type, &value), "Calibrate options");
    return value;
}

}  // namespace

CalibrationOptions readCalibrationOptions(sd_bus_message* message) {
    CalibrationOptions options;
    checkBusCall(sd_bus_message_enter_container(message, 'a', "{sv}"), "Calibrate options");
    int r = 0;
    while ((r = sd_bus_message_enter_container(message, 'e', "sv")) > 0) {
        const char* key = nullptr;
        checkBusCall(sd_bus_message_read(message, "s", &key), "Calibrate options");
        if (std::strcmp(key, bus::kOptionFrames) == 0)
            options.pairsPerStep = readOption<std::uint32_t>(message, key, "u");
        else if (std::strcmp(key, bus::kOptionCardWidthMm) == 0)
            options.cardWidthMm = readOption<double>(message, key, "d");
        else if (std::strcmp(key, bus::kOptionCardHeightMm) == 0)
            options.cardHeightMm = readOption<double>(message, key, "d");
        else if (std::strcmp(key, bus::kOptionViews) == 0)
            options.views = readOption<std::uint32_t>(message, key, "u");
        else if (std::strcmp(key, bus::kOptionViewTimeoutS) == 0)
            options.viewTimeoutS = readOption<double>(message, key, "d");
        else
            throw BusError(SD_BUS_ERROR_INVALID_ARGS,
                           std::string("Unknown Calibrate option \"") + key +
                               "\"; known: frames (u), card_width_mm (d), card_height_mm (d), views (u), "
                               "view_timeout_s (d)");
        checkBusCall(sd_bus_message_exit_container(message), "Calibrate options");
    }
    checkBusCall(r, "Calibrate options");
    checkBusCall(sd_bus_message_exit_container(message), "Calibrate options");
    if (auto problem = options.validate())
        throw BusError(SD_BUS_ERROR_INVALID_ARGS, "Calibrate option " + *problem);
    return options;
}

}  // namespace everytouch::service
