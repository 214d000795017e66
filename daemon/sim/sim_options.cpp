#include "sim/sim_options.h"

#include <charconv>
#include <cmath>
#include <functional>

namespace everytouch::sim {

namespace {

using Setter = std::function<std::optional<std::string>(SimParameters&, std::string_view)>;

struct OptionEntry {
    OptionKey key;
    Setter set;
};

std::optional<double> parseDouble(std::string_view text) {
    double value = 0.0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
        return std::nullopt;
    return value;
}

template <typename Integer>
std::optional<Integer> parseInteger(std::string_view text) {
    Integer value = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size())
        return std::nullopt;
    return value;
}

std::optional<Eigen::Vector3d> parseVector(std::string_view text) {
    Eigen::Vector3d vector;
    for (int i = 0; i < 3; ++i) {
        const size_t colon = text.find(':');
        if ((i < 2) != (colon != std::string_view::npos))
            return std::nullopt;
        const std::optional<double> component = parseDouble(text.substr(0, colon));
        if (!component)
            return std::nullopt;
        vector[i] = *component;
        text = i < 2 ? text.substr(colon + 1) : std::string_view();
    }
    return vector;
}

std::optional<cv::Size> parseSize(std::string_view text) {
    const size_t x = text.find('x');
    if (x == std::string_view::npos)
        return std::nullopt;
    const auto width = parseInteger<int>(text.substr(0, x));
    const auto height = parseInteger<int>(text.substr(x + 1));
    if (!width || !height)
        return std::nullopt;
    return cv::Size(*width, *height);
}

Setter number(double SimParameters::*field) {
    return [field](SimParameters& p, std::string_view text) -> std::optional<std::string> {
        const auto value = parseDouble(text);
        if (!value)
            return "expected a number";
        p.*field = *value;
        return std::nullopt;
    };
}

Setter optionalNumber(std::optional<double> SimParameters::*field) {
    return [field](SimParameters& p, std::string_view text) -> std::optional<std::string> {
        if (text == "auto" || text == "none") {
            p.*field = std::nullopt;
            return std::nullopt;
        }
        const auto value = parseDouble(text);
        if (!value)
            return "expected a number, or auto / none";
        p.*field = *value;
        return std::nullopt;
    };
}

Setter integer(int SimParameters::*field) {
    return [field](SimParameters& p, std::string_view text) -> std::optional<std::string> {
        const auto value = parseInteger<int>(text);
        if (!value)
            return "expected an integer";
        p.*field = *value;
        return std::nullopt;
    };
}

Setter vector(Eigen::Vector3d SimParameters::*field) {
    return [field](SimParameters& p, std::string_view text) -> std::optional<std::string> {
        const auto value = parseVector(text);
        if (!value)
            return "expected three numbers separated by ':' (e.g. 0:-215:455)";
        p.*field = *value;
        return std::nullopt;
    };
}

Setter size(cv::Size SimParameters::*field) {
    return [field](SimParameters& p, std::string_view text) -> std::optional<std::string> {
        const auto value = parseSize(text);
        if (!value)
            return "expected WIDTHxHEIGHT (e.g. 648x488)";
        p.*field = *value;
        return std::nullopt;
    };
}

template <typename Enum>
Setter choice(Enum SimParameters::*field, std::vector<std::pair<std::string, Enum>> names) {
    return [field, names](SimParameters& p, std::string_view text) -> std::optional<std::string> {
        std::string known;
        for (const auto& [name, value] : names) {
            if (text == name) {
                p.*field = value;
                return std::nullopt;
            }
            known += (known.empty() ? "" : ", ") + name;
        }
        return "expected one of " + known;
    };
}

std::optional<std::string> setLight(SimParameters& p, std::string_view text) {
    constexpr double kDarkLux = 3.0, kNormalLux = 150.0;
    if (text == "dark") {
        p.ambientLux = kDarkLux;
        p.ambientChangeLux.reset();
    } else if (text == "normal") {
        p.ambientLux = kNormalLux;
        p.ambientChangeLux.reset();
    } else if (text == "change") {
        p.ambientLux = kNormalLux;
        p.ambientChangeLux = kDarkLux;
    } else {
        return "expected dark, normal or change";
    }
    return std::nullopt;
}

const std::vector<OptionEntry>& entries() {
    static const std::vector<OptionEntry> table = {
        {{"seed", "random seed of pattern, content, motion and noise (integer)"},
         [](SimParameters& p, std::string_view text) -> std::optional<std::string> {
             const auto value = parseInteger<std::uint64_t>(text);
             if (!value)
                 return "expected a non-negative integer";
             p.seed = *value;
             return std::nullopt;
         }},
        {{"start", "start the stream this many seconds into the session (default 0)"},
         number(&SimParameters::startS)},
        {{"duration", "end the stream after this many seconds (default: endless)"},
         optionalNumber(&SimParameters::durationS)},
        {{"stall",
          "the camera delivers no frame from this many seconds into the session on (default: never)"},
         optionalNumber(&SimParameters::stallS)},
        {{"stall_s", "how long the camera stalls, seconds (default 1)"},
         number(&SimParameters::stallDurationS)},
        {{"wrong_size",
          "from this many seconds into the session on, the frames are the sensor's centre quarter (default: "
          "never)"},
         optionalNumber(&SimParameters::wrongSizeS)},
        {{"wrong_size_s", "how long the frames have the wrong size, seconds (default 0.5)"},
         number(&SimParameters::wrongSizeDurationS)},
        {{"knock",
          "the camera is knocked this many seconds into the session: it turns by knock_deg and shifts by "
          "knock_mm, while the calibration stays as it was (default: never)"},
         optionalNumber(&SimParameters::knockS)},
        {{"knock_deg", "how far a knock turns the camera, about a random axis, degrees (default 0.5)"},
         number(&SimParameters::knockDeg)},
        {{"knock_mm", "how far a knock shifts the camera, in a random direction, mm (default 2)"},
         number(&SimParameters::knockMm)},
        {{"table_shift",
          "the table slides this many seconds into the session: it moves by table_shift_mm and turns by "
          "table_shift_deg in its own plane under the rig, whose calibration stays as it was (default: "
          "never)"},
         optionalNumber(&SimParameters::tableShiftS)},
        {{"table_shift_mm", "how far the table slides, in a random direction, mm (default 5)"},
         number(&SimParameters::tableShiftMm)},
        {{"table_shift_deg", "how far the sliding table turns about the vertical, degrees (default 1)"},
         number(&SimParameters::tableShiftDeg)},
        {{"table_tilt",
          "the table tilts this many seconds into the session: it turns by table_tilt_deg about a level axis "
          "through the display's centre under the rig, whose calibration stays as it was (default: never)"},
         optionalNumber(&SimParameters::tableTiltS)},
        {{"table_tilt_deg",
          "how far the table tilts, about a level axis in a random direction, degrees (default 1)"},
         number(&SimParameters::tableTiltDeg)},
        {{"drift_px_per_min",
          "the projector's image creeps across the table at this rate, in a random direction, projector "
          "pixels per minute, while the calibration stays as it was (default 0)"},
         number(&SimParameters::driftPxPerMin)},
        {{"surface", "table surface: gray, yellow or artifacts"},
         choice(&SimParameters::surface,
                std::vector<std::pair<std::string, SurfaceKind>>{{"gray", SurfaceKind::Gray},
                                                                 {"yellow", SurfaceKind::Yellow},
                                                                 {"artifacts", SurfaceKind::Artifacts}})},
        {{"light",
          "room light preset: dark (3 lux), normal (150 lux), change (normal, dark after "
          "ambient_change_s)"},
         setLight},
        {{"content",
          "projected content: auto (the scenario's), grid35, shapes, photo, ui, text, white, gray, "
          "or an image file"},
         [](SimParameters& p, std::string_view text) -> std::optional<std::string> {
             if (text.empty())
                 return "expected a content kind or an image file";
             p.content = std::string(text);
             return std::nullopt;
         }},
        {{"skin", "skin tone: light, medium, tan or dark"},
         choice(&SimParameters::skinTone,
                std::vector<std::pair<std::string, SkinTone>>{{"light", SkinTone::Light},
                                                              {"medium", SkinTone::Medium},
                                                              {"tan", SkinTone::Tan},
                                                              {"dark", SkinTone::Dark}})},
        {{"camera", "sensor colour: bayer (demosaiced to BGR), rgb or mono"},
         choice(
             &SimParameters::cameraColour,
             std::vector<std::pair<std::string, CameraColour>>{
                 {"bayer", CameraColour::Bayer}, {"rgb", CameraColour::Rgb}, {"mono", CameraColour::Mono}})},
        {{"camera_size", "sensor size WxH, pixels"}, size(&SimParameters::cameraSize)},
        {{"camera_focal_mm", "lens focal length, mm"}, number(&SimParameters::cameraFocalMm)},
        {{"camera_pixel_um", "pixel pitch, micrometres"}, number(&SimParameters::cameraPixelUm)},
        {{"camera_position", "camera optical centre x:y:z, table mm"},
         vector(&SimParameters::cameraPosition)},
        {{"camera_target", "table point on the camera's optical axis x:y:z, mm"},
         vector(&SimParameters::cameraTarget)},
        {{"projector_size", "projector panel WxH, pixels"}, size(&SimParameters::projectorSize)},
        {{"projector_focal_px", "projector focal length, panel pixels"},
         number(&SimParameters::projectorFocalPx)},
        {{"projector_principal_row_px", "projector principal point row (lens offset), pixels"},
         number(&SimParameters::projectorPrincipalRowPx)},
        {{"projector_position", "projector optical centre x:y:z, table mm"},
         vector(&SimParameters::projectorPosition)},
        {{"projector_target", "table point hit by the panel's centre x:y:z, mm"},
         vector(&SimParameters::projectorTarget)},
        {{"display_size", "desktop image WxH, pixels"}, size(&SimParameters::displaySize)},
        {{"keystone", "1: the display is keystone-corrected to a rectangle on the table; 0: it is the panel"},
         [](SimParameters& p, std::string_view text) -> std::optional<std::string> {
             if (text != "0" && text != "1")
                 return "expected 0 or 1";
             p.keystoneCorrection = text == "1";
             return std::nullopt;
         }},
        {{"frame_rate", "projector and camera frame rate, Hz"}, number(&SimParameters::frameRate)},
        {{"delta", "code amplitude, projector levels (1..127)"}, integer(&SimParameters::delta)},
        {{"projector_lux", "illuminance of projected white at the display centre, lux"},
         number(&SimParameters::projectorWhiteLux)},
        {{"projector_gamma", "projector transfer exponent"}, number(&SimParameters::projectorGamma)},
        {{"projector_black", "projector black level, fraction of white"},
         number(&SimParameters::projectorBlackLevel)},
        {{"projector_corner_falloff", "relative illuminance of the panel corners"},
         number(&SimParameters::projectorCornerFalloff)},
        {{"projector_defocus_px", "projector blur sigma on the table, panel pixels"},
         number(&SimParameters::projectorDefocusPx)},
        {{"ambient_lux", "room light on the table, lux"}, number(&SimParameters::ambientLux)},
        {{"ambient_colour", "relative R:G:B of the room light"}, vector(&SimParameters::ambientColour)},
        {{"ambient_change_lux", "room light level after the change, lux (none: no change)"},
         optionalNumber(&SimParameters::ambientChangeLux)},
        {{"ambient_change_s", "time of the room light change, seconds"},
         number(&SimParameters::ambientChangeAtS)},
        {{"hand_scale", "hand size relative to an average adult's"}, number(&SimParameters::handScale)},
        {{"skin_scatter_mm", "subsurface scattering sigma R:G:B, mm"}, vector(&SimParameters::skinScatterMm)},
        {{"skin_scatter_fraction", "fraction of skin reflection that scattered inside the skin"},
         number(&SimParameters::skinScatterFraction)},
        {{"sensitivity", "electrons per lux-second for albedo 1 at the image centre"},
         number(&SimParameters::sensitivity)},
        {{"channel_response", "relative R:G:B sensitivity of the colour filters"},
         vector(&SimParameters::channelResponse)},
        {{"full_well", "saturation charge, electrons"}, number(&SimParameters::fullWellElectrons)},
        {{"read_noise", "read noise, electrons rms"}, number(&SimParameters::readNoiseElectrons)},
        {{"gain_db", "analogue gain, dB"}, number(&SimParameters::gainDb)},
        {{"exposure_ms", "exposure time, ms (auto: metered once at the start)"},
         optionalNumber(&SimParameters::exposureMs)},
        {{"max_exposure_ms", "longest exposure auto metering may choose, ms"},
         number(&SimParameters::maxExposureMs)},
        {{"auto_exposure_level", "metering target, fraction of full scale"},
         number(&SimParameters::autoExposureLevel)},
        {{"black_level_dn", "camera black level offset, DN"}, number(&SimParameters::blackLevelDn)},
        {{"prnu", "photo-response non-uniformity, relative rms"}, number(&SimParameters::prnu)},
        {{"camera_defocus_px", "camera blur sigma, pixels"}, number(&SimParameters::cameraDefocusPx)},
        {{"vignetting_power", "exponent of the cos(field angle) falloff"},
         number(&SimParameters::vignettingPower)},
        {{"pixel_samples", "n for n x n samples per camera pixel on the table"},
         integer(&SimParameters::pixelSamples)},
        {{"motion_samples", "most instants per exposure for moving hands (odd; 1: no motion blur)"},
         integer(&SimParameters::motionSamples)},
    };
    return table;
}

}  // namespace

const std::vector<OptionKey>& optionKeys() {
    static const std::vector<OptionKey> keys = [] {
        std::vector<OptionKey> list;
        for (const OptionEntry& entry : entries())
            list.push_back(entry.key);
        return list;
    }();
    return keys;
}

std::optional<std::string> applyOption(SimParameters& parameters, std::string_view key,
                                       std::string_view value) {
    for (const OptionEntry& entry : entries())
        if (entry.key.name == key)
            return entry.set(parameters, value);
    std::string known;
    for (const OptionEntry& entry : entries())
        known += (known.empty() ? "" : ", ") + entry.key.name;
    return "unknown key; known keys: " + known;
}

}  // namespace everytouch::sim
