#include "io/touch_log.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <system_error>

#include <nlohmann/json.hpp>

#include "io/input_error.h"

namespace everytouch::io {

namespace {

// Two decimals keep sub-pixel and sub-millimetre precision without float noise in the log.
double rounded(double value) {
    return std::round(value * 100.0) / 100.0;
}

nlohmann::json toJson(const core::Contact& contact) {
    nlohmann::json object = {{"id", contact.id},
                             {"x", rounded(contact.x)},
                             {"y", rounded(contact.y)},
                             {"touch", contact.touching},
                             {"height_mm", rounded(contact.heightMm)}};
    if (contact.palm)
        object["palm"] = true;
    return object;
}

template <typename T>
T requireField(const nlohmann::json& object, const char* key, const std::string& input,
               const std::string& where) {
    const auto it = object.find(key);
    if (it == object.end())
        throw InputError(input, where, std::string(key) + ": missing");
    if constexpr (std::is_same_v<T, bool>) {
        if (!it->is_boolean())
            throw InputError(input, where, std::string(key) + ": expected true or false");
    } else if constexpr (std::is_floating_point_v<T>) {
        if (!it->is_number() || !std::isfinite(it->get<double>()))
            throw InputError(input, where, std::string(key) + ": expected a finite number");
    } else {
        if (!it->is_number_unsigned() && !(it->is_number_integer() && it->get<std::int64_t>() >= 0))
            throw InputError(input, where, std::string(key) + ": expected a non-negative integer");
    }
    return it->get<T>();
}

}  // namespace

TouchLogWriter::TouchLogWriter(const std::filesystem::path& path) {
    if (path == "-") {
        file_ = stdout;
        return;
    }
    file_ = std::fopen(path.c_str(), "we");
    if (!file_)
        throw std::system_error(errno, std::generic_category(),
                                "Failed to open the touch log " + path.string());
    ownsFile_ = true;
}

TouchLogWriter::~TouchLogWriter() {
    if (ownsFile_)
        std::fclose(file_);
    else
        std::fflush(file_);
}

void TouchLogWriter::publish(std::uint64_t frameIndex, std::int64_t timestampUs,
                             const core::Contacts& contacts) {
    if (wroteAny_ ? contacts == last_ : contacts.empty())
        return;
    nlohmann::json line = {
        {"index", frameIndex}, {"t_us", timestampUs}, {"contacts", nlohmann::json::array()}};
    for (const core::Contact& contact : contacts)
        line["contacts"].push_back(toJson(contact));
    const std::string text = line.dump() + "\n";
    std::fwrite(text.data(), 1, text.size(), file_);
    std::fflush(file_);
    last_ = contacts;
    wroteAny_ = true;
}

std::vector<TouchLogEntry> readTouchLog(const std::filesystem::path& path) {
    const std::string input = path.string();
    std::ifstream stream(path);
    if (!stream)
        throw InputError(input, "", "cannot be opened");
    std::vector<TouchLogEntry> entries;
    std::string text;
    for (size_t number = 1; std::getline(stream, text); ++number) {
        if (text.empty())
            continue;
        const std::string where = "line " + std::to_string(number);
        const nlohmann::json line = nlohmann::json::parse(text, nullptr, false);
        if (line.is_discarded() || !line.is_object())
            throw InputError(input, where, "not a JSON object");
        TouchLogEntry entry;
        entry.line = number;
        entry.index = requireField<std::uint64_t>(line, "index", input, where);
        const auto time = line.find("t_us");
        if (time == line.end() || !time->is_number_integer())
            throw InputError(input, where, "t_us: expected an integer");
        entry.timestampUs = time->get<std::int64_t>();
        const auto contacts = line.find("contacts");
        if (contacts == line.end() || !contacts->is_array())
            throw InputError(input, where, "contacts: expected a list");
        for (const nlohmann::json& object : *contacts) {
            if (!object.is_object())
                throw InputError(input, where, "contacts: expected objects");
            core::Contact contact;
            contact.id = requireField<std::uint32_t>(object, "id", input, where);
            contact.x = requireField<double>(object, "x", input, where);
            contact.y = requireField<double>(object, "y", input, where);
            contact.touching = requireField<bool>(object, "touch", input, where);
            contact.heightMm = requireField<double>(object, "height_mm", input, where);
            if (const auto palm = object.find("palm"); palm != object.end())
                contact.palm = palm->is_boolean() && palm->get<bool>();
            entry.contacts.push_back(contact);
        }
        // The release of every contact when the stream ends carries the last frame's index again.
        if (!entries.empty() && entry.index < entries.back().index)
            throw InputError(input, where, "index: must not decrease from line to line");
        entries.push_back(std::move(entry));
    }
    return entries;
}

}  // namespace everytouch::io
