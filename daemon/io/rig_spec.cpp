#include "io/rig_spec.h"

#include "io/input_error.h"

namespace everytouch::io {

namespace {

constexpr const char* kSyntax =
    "expected sim[:SCENARIO][,key=value...], replay:DIR, aravis[:ID] or v4l2:/dev/videoN";

std::vector<std::string> splitOnComma(std::string_view text) {
    std::vector<std::string> parts;
    size_t start = 0;
    while (true) {
        const size_t comma = text.find(',', start);
        parts.emplace_back(
            text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
        if (comma == std::string_view::npos)
            return parts;
        start = comma + 1;
    }
}

}  // namespace

RigSpec RigSpec::parse(std::string_view text) {
    const std::string input = "--rig " + std::string(text);
    const size_t colon = text.find(':');
    const std::string_view kind = text.substr(0, colon);
    const std::string_view rest =
        colon == std::string_view::npos ? std::string_view() : text.substr(colon + 1);
    RigSpec spec;
    if (kind == "sim") {
        spec.kind = Kind::Sim;
        if (rest.empty())
            return spec;
        for (const std::string& part : splitOnComma(rest)) {
            const size_t equals = part.find('=');
            if (equals == std::string::npos) {
                if (!spec.target.empty() || !spec.options.empty())
                    throw InputError(input, "",
                                     "the scenario must come first and only once: " + std::string(kSyntax));
                if (part.empty())
                    throw InputError(input, "", "empty scenario name");
                spec.target = part;
                continue;
            }
            const std::string key = part.substr(0, equals);
            if (key.empty())
                throw InputError(input, "", "option \"" + part + "\" has no key");
            for (const auto& [existing, value] : spec.options)
                if (existing == key)
                    throw InputError(input, key, "given twice");
            spec.options.emplace_back(key, part.substr(equals + 1));
        }
        return spec;
    }
    if (kind == "replay") {
        spec.kind = Kind::Replay;
        if (rest.empty())
            throw InputError(input, "", "replay needs a recording directory: replay:DIR");
    } else if (kind == "aravis") {
        spec.kind = Kind::Aravis;
    } else if (kind == "v4l2") {
        spec.kind = Kind::V4l2;
        if (rest.empty())
            throw InputError(input, "", "v4l2 needs a device node: v4l2:/dev/videoN");
    } else {
        throw InputError(input, "", kSyntax);
    }
    spec.target = std::string(rest);
    return spec;
}

std::string RigSpec::toString() const {
    switch (kind) {
        case Kind::Sim: {
            std::string text = "sim";
            std::string separator = ":";
            if (!target.empty()) {
                text += separator + target;
                separator = ",";
            }
            for (const auto& [key, value] : options) {
                text += separator + key + "=" + value;
                separator = ",";
            }
            return text;
        }
        case Kind::Replay:
            return "replay:" + target;
        case Kind::Aravis:
            return target.empty() ? "aravis" : "aravis:" + target;
        case Kind::V4l2:
            return "v4l2:" + target;
    }
    return {};
}

}  // namespace everytouch::io
