#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

namespace everytouch::core {

// Why an operation could not give its result: a sentence naming the input and what is wrong with it, fit to
// be shown to the user (callers prefix what they were doing: "the card: " + message).
struct Failure {
    std::string message;
};

// The value of an operation that can fail on its input, or the Failure that prevented it: the shape of
// std::expected<T, Failure>, which C++20 does not have. Reading the side that is not there is a programming
// error and throws std::logic_error. docs/architecture.md, "Errors", says when to use it.
template <typename T>
class [[nodiscard]] Result {
    static_assert(!std::is_same_v<std::remove_cv_t<T>, Failure>,
                  "a Result holds a value or a Failure, not both");

public:
    Result(T value) : state_(std::in_place_index<0>, std::move(value)) {}
    Result(Failure failure) : state_(std::in_place_index<1>, std::move(failure)) {}

    bool ok() const { return state_.index() == 0; }

    T& value() & { return *checkedValue(); }
    const T& value() const& { return *checkedValue(); }
    T&& value() && { return std::move(*checkedValue()); }
    T* operator->() { return checkedValue(); }
    const T* operator->() const { return checkedValue(); }

    const Failure& failure() const {
        if (ok())
            throw std::logic_error("Result::failure() of a result that holds a value");
        return *std::get_if<1>(&state_);
    }

private:
    T* checkedValue() { return const_cast<T*>(std::as_const(*this).checkedValue()); }
    const T* checkedValue() const {
        if (!ok())
            throw std::logic_error("Result::value() of a failure: " + std::get_if<1>(&state_)->message);
        return std::get_if<0>(&state_);
    }

    std::variant<T, Failure> state_;
};

// The outcome of an operation that gives no value: success, or the Failure that prevented it.
template <>
class [[nodiscard]] Result<void> {
public:
    Result() = default;
    Result(Failure failure) : failure_(std::move(failure)) {}

    bool ok() const { return !failure_; }

    const Failure& failure() const {
        if (ok())
            throw std::logic_error("Result::failure() of a success");
        return *failure_;
    }

private:
    std::optional<Failure> failure_;
};

using Status = Result<void>;

}  // namespace everytouch::core
