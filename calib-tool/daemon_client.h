#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <systemd/sd-bus.h>

#include "io/handles.h"

namespace everytouch::calib {

// Exit statuses of everytouch-calib, as --help and everytouch-calib(1) list them.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;
inline constexpr int kExitNotRunning = 3;
inline constexpr int kExitDenied = 4;

// Something the user must act on: the words to print and the exit status.
struct Failure {
    int exitStatus = kExitFailure;
    std::string message;
};

using PropertyValue = std::variant<std::string, bool, double, std::uint32_t, std::uint64_t>;

// One finger as the daemon's Contacts signal carries it.
struct ContactReading {
    std::uint32_t id = 0;   // stable while the finger is tracked
    double x = 0.0;         // display pixels
    double y = 0.0;         // display pixels
    bool touching = false;  // at or below the touch height
    double heightMm = 0.0;  // the finger pad's height above the table
};

// A connection to everytouchd over the system bus. Every call returns a Failure phrased for the user, with
// `action` ("Setting the touch height") naming what was attempted.
class DaemonClient {
public:
    // Connects and checks that everytouchd is there.
    static std::variant<DaemonClient, Failure> connect();

    std::variant<std::map<std::string, PropertyValue>, Failure> allProperties();

    // The display the touches are reported in, from the active calibration; zero while not calibrated.
    struct Display {
        std::uint32_t widthPx = 0;
        std::uint32_t heightPx = 0;
        double widthMm = 0.0;  // on the table
        double heightMm = 0.0;
    };
    std::variant<Display, Failure> display();
    std::optional<Failure> setTouchHeightMm(double heightMm);
    std::optional<Failure> snapshot(const std::string& what, int fd);
    std::optional<Failure> saveCalibration();
    // Has the projector show the accuracy test's circles (until showAccuracyTargets(false) or this client
    // leaves the bus), or the display again.
    std::optional<Failure> showAccuracyTargets(bool show);

    struct CalibrationOptions {
        std::optional<std::uint32_t> frames;
        std::optional<double> cardWidthMm;
        std::optional<double> cardHeightMm;
        std::optional<std::uint32_t> views;
        std::optional<double> viewTimeoutS;
    };
    using ProgressHandler =
        std::function<void(const std::string& step, double fraction, const std::string& message)>;
    struct CalibrationResult {
        bool ok = false;
        std::string message;
        double rmsPx = 0.0;
    };
    // Starts a calibration and follows its signals until it finishes.
    std::variant<CalibrationResult, Failure> calibrate(const std::string& step,
                                                       const CalibrationOptions& options,
                                                       const ProgressHandler& onProgress);

    struct ContactsOptions {
        std::optional<std::uint64_t> count;  // end after this many Contacts signals
        std::optional<double> durationS;     // end after this many seconds
    };
    // What the daemon reported last, handed over after each Contacts signal and each new frame rate.
    struct ContactsUpdate {
        double seconds = 0.0;          // since following began
        bool contactsChanged = false;  // false: only the frame rate was read again
        std::vector<ContactReading> contacts;
        double frameRate = 0.0;  // frames per second, read once a second
    };
    // Returns false to stop following.
    using ContactsHandler = std::function<bool(const ContactsUpdate& update)>;
    // Follows the Contacts signal until `options` are met, `onUpdate` returns false or SIGINT or SIGTERM
    // arrives (then nothing is returned), or until the daemon leaves the bus (a Failure). `onUpdate` runs
    // outside sd-bus callbacks.
    std::optional<Failure> followContacts(const ContactsOptions& options, const ContactsHandler& onUpdate);

private:
    explicit DaemonClient(io::Bus bus) : bus_(std::move(bus)) {}

    // Turns a failed call into words; `action` says what was attempted.
    static Failure explain(const io::UniqueBusError& error, int r, const std::string& action);

    io::Bus bus_;
};

}  // namespace everytouch::calib
