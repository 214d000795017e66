#pragma once

#include <optional>

#include <nlohmann/json.hpp>

namespace everytouch::eval {

// A figure that could not be measured is null in the reports' JSON, not a number that looks measured.
inline nlohmann::json orNull(const std::optional<double>& value) {
    return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

}  // namespace everytouch::eval
