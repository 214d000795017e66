#include "service/config.h"

#include <ini.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "io/handles.h"
#include "io/input_error.h"
#include "io/rig_spec.h"

namespace everytouch::service {

namespace {

using File = io::UniqueHandle<std::FILE, std::fclose>;

// A value the key does not accept; the message says what it accepts.
struct BadValue {
    std::string problem;
};

struct KeySpec {
    const char* section;
    const char* key;
    // Sets the key from its text; throws BadValue. An empty text restores the default.
    std::function<void(DaemonConfig&, const std::string&)> apply;
};

std::optional<bool> parseBoolean(const std::string& text) {
    for (const char* word : {"yes", "true", "on", "1"})
        if (text == word)
            return true;
    for (const char* word : {"no", "false", "off", "0"})
        if (text == word)
            return false;
    return std::nullopt;
}

// A number from `minimum` to `maximum`, of `unit` (its name in words for "expected a number of", its symbol
// for the range).
double parseQuantity(const std::string& text, double minimum, double maximum, const std::string& unitWords,
                     const std::string& unitSymbol) {
    double value = 0.0;
    const char* end = text.data() + text.size();
    const auto [stop, error] = std::from_chars(text.data(), end, value);
    if (error != std::errc() || stop != end || !std::isfinite(value))
        throw BadValue{"expected a number of " + unitWords + ", found \"" + text + "\""};
    if (value < minimum || value > maximum) {
        char range[64];
        std::snprintf(range, sizeof range, "%g to %g", minimum, maximum);
        throw BadValue{"must be from " + std::string(range) + " " + unitSymbol + ", found " + text};
    }
    return value;
}

// A whole number from `minimum` to `maximum`; `what` names it for the message ("a whole number of levels").
template <typename Integer>
Integer parseWholeNumber(const std::string& text, Integer minimum, Integer maximum, const std::string& what) {
    Integer value = 0;
    const char* end = text.data() + text.size();
    const auto [stop, error] = std::from_chars(text.data(), end, value);
    if (error != std::errc() || stop != end || value < minimum || value > maximum)
        throw BadValue{"expected " + what + " from " + std::to_string(minimum) + " to " +
                       std::to_string(maximum) + ", found \"" + text + "\""};
    return value;
}

// An optional camera setting: empty leaves it to the camera.
std::optional<double> parseCameraQuantity(const std::string& text, double minimum, double maximum,
                                          const std::string& unitWords, const std::string& unitSymbol) {
    if (text.empty())
        return std::nullopt;
    return parseQuantity(text, minimum, maximum, unitWords, unitSymbol);
}

const std::vector<KeySpec>& keySpecs() {
    static const std::vector<KeySpec> specs = {
        {"Camera", "Rig",
         [](DaemonConfig& config, const std::string& value) {
             if (!value.empty()) {
                 try {
                     io::RigSpec::parse(value);
                 } catch (const io::InputError& error) {
                     std::string problem = error.what();
                     const std::string prefix = "--rig " + value + ": ";
                     if (problem.starts_with(prefix))
                         problem.erase(0, prefix.size());
                     throw BadValue{problem};
                 }
             }
             config.rig = value;
         }},
        {"Camera", "PixelFormat",
         [](DaemonConfig& config, const std::string& value) {
             config.camera.pixels.reset();
             if (value.empty())
                 return;
             config.camera.pixels = io::parseCameraPixels(value);
             if (!config.camera.pixels)
                 throw BadValue{"expected one of " + io::cameraPixelsNames() + ", found \"" + value + "\""};
         }},
        {"Camera", "FrameRate",
         [](DaemonConfig& config, const std::string& value) {
             config.camera.frameRate =
                 parseCameraQuantity(value, kMinFrameRate, kMaxFrameRate, "frames per second", "frames/s");
         }},
        {"Camera", "ExposureUs",
         [](DaemonConfig& config, const std::string& value) {
             config.camera.exposureUs =
                 parseCameraQuantity(value, kMinExposureUs, kMaxExposureUs, "microseconds", "us");
         }},
        {"Camera", "GainDb",
         [](DaemonConfig& config, const std::string& value) {
             config.camera.gainDb = parseCameraQuantity(value, kMinGainDb, kMaxGainDb, "decibels", "dB");
         }},
        {"Camera", "Region",
         [](DaemonConfig& config, const std::string& value) {
             config.camera.region.reset();
             if (value.empty())
                 return;
             static const std::regex geometry(R"((\d{1,5})x(\d{1,5})(?:\+(\d{1,5})\+(\d{1,5}))?)");
             std::smatch match;
             if (!std::regex_match(value, match, geometry))
                 throw BadValue{"expected WIDTHxHEIGHT or WIDTHxHEIGHT+X+Y in pixels, found \"" + value +
                                "\""};
             const cv::Rect region(match[3].matched ? std::stoi(match[3]) : 0,
                                   match[4].matched ? std::stoi(match[4]) : 0, std::stoi(match[1]),
                                   std::stoi(match[2]));
             if (region.width < kMinRegionSide || region.height < kMinRegionSide)
                 throw BadValue{"must be at least " + std::to_string(kMinRegionSide) +
                                " pixels wide and high, found " + value};
             config.camera.region = region;
         }},
        {"Camera", "Trigger",
         [](DaemonConfig& config, const std::string& value) {
             config.camera.trigger.reset();
             if (value.empty())
                 return;
             static const std::regex source(R"([A-Za-z][A-Za-z0-9_]{0,31})");
             if (!std::regex_match(value, source))
                 throw BadValue{"expected off or a trigger source such as Line0, found \"" + value + "\""};
             config.camera.trigger = value;
         }},
        {"Touch", "HeightMm",
         [](DaemonConfig& config, const std::string& value) {
             config.touchHeightMm = value.empty() ? DaemonConfig().touchHeightMm
                                                  : parseQuantity(value, kMinTouchHeightMm, kMaxTouchHeightMm,
                                                                  "millimetres", "mm");
         }},
        {"Output", "Uinput",
         [](DaemonConfig& config, const std::string& value) {
             if (value.empty()) {
                 config.uinput.reset();
                 return;
             }
             config.uinput = parseBoolean(value);
             if (!config.uinput)
                 throw BadValue{"expected yes or no, found \"" + value + "\""};
         }},
        {"Calibration", "Path",
         [](DaemonConfig& config, const std::string& value) {
             if (!value.empty() && value.front() != '/')
                 throw BadValue{"expected an absolute path, found \"" + value + "\""};
             config.calibrationPath = value;
         }},
        {"Calibration", "Correct",
         [](DaemonConfig& config, const std::string& value) {
             if (value.empty()) {
                 config.correctCalibration = DaemonConfig().correctCalibration;
                 return;
             }
             const std::optional<bool> correct = parseBoolean(value);
             if (!correct)
                 throw BadValue{"expected yes or no, found \"" + value + "\""};
             config.correctCalibration = *correct;
         }},
        {"Projector", "Output",
         [](DaemonConfig& config, const std::string& value) {
             const std::optional<ProjectorOutput> output =
                 value.empty() ? ProjectorOutput::None : parseProjectorOutput(value);
             if (!output)
                 throw BadValue{"expected none, external, window or overlay, found \"" + value + "\""};
             config.projector.output = *output;
         }},
        {"Projector", "Display",
         [](DaemonConfig& config, const std::string& value) { config.projector.display = value; }},
        {"Projector", "Delta",
         [](DaemonConfig& config, const std::string& value) {
             config.projector.delta = value.empty()
                                          ? ProjectorConfig().delta
                                          : parseWholeNumber(value, 1, 127, "a whole number of levels");
         }},
        {"Projector", "Seed",
         [](DaemonConfig& config, const std::string& value) {
             config.projector.seed =
                 value.empty()
                     ? ProjectorConfig().seed
                     : parseWholeNumber(value, std::uint64_t{0}, std::numeric_limits<std::uint64_t>::max(),
                                        "a whole number");
         }},
    };
    return specs;
}

std::string knownKeys(const std::string& section) {
    std::string keys;
    for (const KeySpec& spec : keySpecs())
        if (section.empty() || section == spec.section)
            keys += (keys.empty() ? "" : ", ") + std::string(spec.key) + "=";
    return keys;
}

bool isKnownSection(const std::string& section) {
    return std::any_of(keySpecs().begin(), keySpecs().end(),
                       [&](const KeySpec& spec) { return section == spec.section; });
}

// inih reads lines through readLine so that every key knows its line number; the first problem wins.
struct ParseState {
    std::FILE* file = nullptr;
    std::string path;
    DaemonConfig* config = nullptr;
    int line = 0;
    int errorLine = 0;  // 0 while no problem was found
    std::string errorField;
    std::string errorProblem;

    void fail(const std::string& field, const std::string& problem) {
        if (errorLine != 0)
            return;
        errorLine = line;
        errorField = field;
        errorProblem = problem;
    }
};

char* readLine(char* buffer, int size, void* stream) {
    auto* state = static_cast<ParseState*>(stream);
    if (!std::fgets(buffer, size, state->file))
        return nullptr;
    ++state->line;
    const size_t length = std::strlen(buffer);
    if (length > 0 && buffer[length - 1] != '\n' && !std::feof(state->file)) {
        state->fail("", "line longer than " + std::to_string(size - 2) + " characters");
        int c = 0;
        while ((c = std::fgetc(state->file)) != EOF && c != '\n') {
        }
        buffer[0] = '\0';
    }
    return buffer;
}

int onEntry(void* user, const char* sectionText, const char* keyText, const char* valueText) {
    auto* state = static_cast<ParseState*>(user);
    const std::string section = sectionText, key = keyText, value = valueText;
    const std::string field = section.empty() ? key : "[" + section + "] " + key;
    if (section.empty()) {
        state->fail(
            field,
            "not inside a [Section]; sections are [Camera], [Touch], [Output], [Calibration], [Projector]");
        return 0;
    }
    if (!isKnownSection(section)) {
        state->fail(field, "unknown section [" + section +
                               "]; known: [Camera], [Touch], [Output], [Calibration], [Projector]");
        return 0;
    }
    for (const KeySpec& spec : keySpecs()) {
        if (section != spec.section || key != spec.key)
            continue;
        try {
            spec.apply(*state->config, value);
        } catch (const BadValue& bad) {
            state->fail(field, bad.problem);
            return 0;
        }
        return 1;
    }
    state->fail(field, "unknown key; [" + section + "] knows " + knownKeys(section));
    return 0;
}

void parseFile(const std::filesystem::path& path, DaemonConfig& config) {
    File file(std::fopen(path.c_str(), "re"));
    if (!file)
        throw io::InputError(path.string(), "", std::string("cannot be read: ") + std::strerror(errno));
    ParseState state;
    state.file = file.get();
    state.path = path.string();
    state.config = &config;
    // inih returns the line of the first problem, its own (a malformed line) or one onEntry reported.
    const int result = ini_parse_stream(readLine, &state, onEntry, &state);
    if (result < 0)
        throw io::InputError(state.path, "", "cannot be parsed");
    if (result > 0 && (state.errorLine == 0 || result < state.errorLine))
        throw io::InputError(state.path + ":" + std::to_string(result), "",
                             "expected [Section], Key=value, a comment or an empty line");
    if (state.errorLine != 0)
        throw io::InputError(state.path + ":" + std::to_string(state.errorLine), state.errorField,
                             state.errorProblem);
}

}  // namespace

std::vector<std::pair<std::string, std::string>> configKeys() {
    std::vector<std::pair<std::string, std::string>> keys;
    for (const KeySpec& spec : keySpecs())
        keys.emplace_back(spec.section, spec.key);
    return keys;
}

std::filesystem::path dropInDirectory(const std::filesystem::path& mainFile) {
    return mainFile.string() + ".d";
}

std::optional<ProjectorOutput> parseProjectorOutput(std::string_view name) {
    if (name == "none")
        return ProjectorOutput::None;
    if (name == "external")
        return ProjectorOutput::External;
    if (name == "window")
        return ProjectorOutput::Window;
    if (name == "overlay")
        return ProjectorOutput::Overlay;
    return std::nullopt;
}

DaemonConfig loadConfig(const std::filesystem::path& mainFile, bool mustExist) {
    DaemonConfig config;
    std::error_code error;
    if (std::filesystem::exists(mainFile, error))
        parseFile(mainFile, config);
    else if (mustExist)
        throw io::InputError(mainFile.string(), "", "no such file");

    std::vector<std::filesystem::path> dropIns;
    const std::filesystem::path directory = dropInDirectory(mainFile);
    if (std::filesystem::is_directory(directory, error))
        for (const auto& entry : std::filesystem::directory_iterator(directory))
            if (entry.path().extension() == ".conf" && !entry.is_directory())
                dropIns.push_back(entry.path());
    std::sort(dropIns.begin(), dropIns.end(),
              [](const auto& a, const auto& b) { return a.filename() < b.filename(); });
    for (const std::filesystem::path& dropIn : dropIns)
        parseFile(dropIn, config);
    return config;
}

}  // namespace everytouch::service
