#include "sim/scenario.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/core.hpp>

#include "core/geometry.h"
#include "sim/calibration_scenarios.h"
#include "sim/easing.h"

namespace everytouch::sim {

namespace {

constexpr double kHoverMm = 35.0;      // height of a finger travelling between taps
constexpr double kEnterSeconds = 1.0;  // a hand coming into view or leaving it
constexpr double kPointingPitchDeg = 30.0;
constexpr double kUserYawDeg = -90.0;  // a hand of the user at +y points towards -y

// Random numbers of one cycle of one scenario.
cv::RNG cycleRng(std::uint64_t seed, int scenarioId, long cycle) {
    std::uint64_t state = seed * 0x9E3779B97F4A7C15ull +
                          static_cast<std::uint64_t>(scenarioId) * 0xBF58476D1CE4E5B9ull +
                          static_cast<std::uint64_t>(cycle) * 0x94D049BB133111EBull;
    state ^= state >> 31;
    return cv::RNG(state | 1);
}

// Where the display's pixels are on the table, and where hands come from.
class Stage {
public:
    explicit Stage(const ScenarioContext& context)
        : displayToTable_(context.calibration.displayToTableHomography()),
          displaySize_(context.calibration.displaySize),
          handScale_(context.handScale) {}

    Eigen::Vector3d onTable(const cv::Point2d& display, double heightMm = 0.0) const {
        const Eigen::Vector2d table = core::applyHomography(displayToTable_, {display.x, display.y});
        return {table.x(), table.y(), heightMm};
    }
    Eigen::Vector3d centre(double heightMm = 0.0) const {
        return onTable({displaySize_.width / 2.0, displaySize_.height / 2.0}, heightMm);
    }
    // A point beyond the display's edge on the user's side, out of the camera's view.
    Eigen::Vector3d offstage(double x) const {
        const double userEdge =
            onTable({displaySize_.width / 2.0, static_cast<double>(displaySize_.height)}).y();
        return {x, userEdge + 330.0, 160.0};
    }
    cv::Size displaySize() const { return displaySize_; }
    double handScale() const { return handScale_; }

private:
    Eigen::Matrix3d displayToTable_;
    cv::Size displaySize_;
    double handScale_;
};

// A fingertip moving through keyframes: smoothly (minimum jerk) between them, or at constant speed when the
// keyframe says so.
class Track {
public:
    struct Key {
        double t;
        Eigen::Vector3d pad;
        double yawDeg;
        bool linear;  // constant speed from this key to the next
    };

    void add(double t, const Eigen::Vector3d& pad, double yawDeg, bool linear = false) {
        keys_.push_back({std::max(t, keys_.empty() ? t : keys_.back().t), pad, yawDeg, linear});
    }
    double end() const { return keys_.empty() ? 0.0 : keys_.back().t; }
    const Key& last() const { return keys_.back(); }

    void at(double t, Eigen::Vector3d& pad, double& yawDeg) const {
        if (t <= keys_.front().t) {
            pad = keys_.front().pad, yawDeg = keys_.front().yawDeg;
            return;
        }
        for (size_t i = 1; i < keys_.size(); ++i) {
            if (t > keys_[i].t)
                continue;
            const Key& a = keys_[i - 1];
            const Key& b = keys_[i];
            const double span = b.t - a.t;
            const double x = span > 0.0 ? (t - a.t) / span : 1.0;
            const double s = a.linear ? x : smootherStep(x);
            pad = a.pad + (b.pad - a.pad) * s;
            yawDeg = a.yawDeg + (b.yawDeg - a.yawDeg) * s;
            return;
        }
        pad = keys_.back().pad, yawDeg = keys_.back().yawDeg;
    }

private:
    std::vector<Key> keys_;
};

HandPose pointingHand(const Eigen::Vector3d& pad, double yawDeg, double scale) {
    HandPose pose;
    pose.scale = scale;
    for (int f = 0; f < kFingerCount; ++f)
        pose.fingers[f] = pointingJoints(static_cast<Finger>(f));
    pose.presented[static_cast<int>(Finger::Index)] = true;
    pose.forearmElevationDeg = 10.0;
    pose.place(Eigen::Vector3d::Zero(), yawDeg, kPointingPitchDeg);
    movePadTo(pose, Finger::Index, pad);
    return pose;
}

// A scenario driven by one pointing index finger along a track built per cycle.
class PointingScenario : public Scenario {
public:
    PointingScenario(const ScenarioContext& context, int id, ContentKind content)
        : stage_(context), seed_(context.seed), id_(id), content_(content) {}

    SceneState at(double seconds) const override {
        const double cycle = cycleSeconds();
        const long index = static_cast<long>(std::floor(seconds / cycle));
        Track track = buildTrack(index);
        SceneState state;
        state.content = content_;
        state.contentVariant = static_cast<int>(index);
        Eigen::Vector3d pad;
        double yaw = 0.0;
        track.at(seconds - index * cycle, pad, yaw);
        state.hands.push_back(pointingHand(pad, yaw, stage_.handScale()));
        return state;
    }
    double cycleSeconds() const override { return buildTrack(0).end(); }

protected:
    virtual Track buildTrack(long cycle) const = 0;

    Stage stage_;
    std::uint64_t seed_;
    int id_;
    ContentKind content_;
};

// The paper's Fig. 15 experiment: tap the circles one by one; each tap approaches from the travelling height,
// sometimes hovers low before touching, dwells, and lifts.
class Grid35Scenario final : public PointingScenario {
public:
    Grid35Scenario(const ScenarioContext& context, int taps)
        : PointingScenario(context, 1, ContentKind::Grid35), taps_(taps) {}

private:
    static constexpr double kSlotSeconds = 1.5;

    Track buildTrack(long cycle) const override {
        cv::RNG rng = cycleRng(seed_, id_, cycle);
        const std::vector<cv::Point2d> centres = grid35Centres(stage_.displaySize());
        const int first =
            taps_ < static_cast<int>(centres.size()) ? rng.uniform(0, static_cast<int>(centres.size())) : 0;
        Track track;
        const Eigen::Vector3d start = stage_.onTable(centres[first], kHoverMm);
        track.add(0.0, stage_.offstage(start.x()), kUserYawDeg);
        for (int i = 0; i < taps_; ++i) {
            const cv::Point2d& centre = centres[(first + i) % centres.size()];
            const double base = kEnterSeconds + i * kSlotSeconds;
            const double yaw = kUserYawDeg + rng.gaussian(6.0);
            const Eigen::Vector3d aim =
                stage_.onTable(centre) + Eigen::Vector3d(rng.gaussian(1.2), rng.gaussian(1.2), 0);
            const double hoverLow = rng.uniform(5.0, 12.0);
            const double pause = rng.uniform(0.0, 0.2);
            const double dwell = rng.uniform(0.18, 0.32);
            track.add(base, stage_.onTable(centre, kHoverMm), yaw);
            track.add(base + 0.35, aim + Eigen::Vector3d(0, 0, hoverLow), yaw);
            track.add(base + 0.45 + pause, aim + Eigen::Vector3d(0, 0, hoverLow), yaw);
            track.add(base + 0.57 + pause, aim, yaw);
            track.add(base + 0.57 + pause + dwell, aim, yaw);
            track.add(base + 0.77 + pause + dwell, aim + Eigen::Vector3d(0, 0, kHoverMm), yaw);
        }
        const double end = kEnterSeconds + taps_ * kSlotSeconds;
        track.add(end, track.last().pad, track.last().yawDeg);
        track.add(end + kEnterSeconds, stage_.offstage(track.last().pad.x()), kUserYawDeg);
        return track;
    }

    int taps_;
};

// The paper's Fig. 17 experiment: drag the index along a square, a right triangle and a circle.
class DragScenario final : public PointingScenario {
public:
    explicit DragScenario(const ScenarioContext& context)
        : PointingScenario(context, 2, ContentKind::Shapes) {}

private:
    static constexpr double kSpeedMmPerS = 60.0;

    Track buildTrack(long cycle) const override {
        cv::RNG rng = cycleRng(seed_, id_, cycle);
        Track track;
        const auto shapes = dragShapes(stage_.displaySize());
        double t = 0.0;
        const Eigen::Vector3d first = stage_.onTable(shapes.front().front(), 30.0);
        track.add(t, stage_.offstage(first.x()), kUserYawDeg);
        t += kEnterSeconds;
        for (const auto& shape : shapes) {
            const double yaw = kUserYawDeg + rng.gaussian(5.0);
            const Eigen::Vector3d start = stage_.onTable(shape.front());
            track.add(t, start + Eigen::Vector3d(0, 0, 30.0), yaw);
            t += 0.45;
            track.add(t, start, yaw);
            t += 0.15;
            Eigen::Vector3d previous = start;
            track.add(t, start, yaw, true);
            for (size_t i = 1; i < shape.size(); ++i) {
                const bool closing = i + 1 == shape.size();
                const Eigen::Vector3d point =
                    closing ? start
                            : Eigen::Vector3d(stage_.onTable(shape[i]) +
                                              Eigen::Vector3d(rng.gaussian(0.8), rng.gaussian(0.8), 0.0));
                t += (point - previous).norm() / kSpeedMmPerS;
                track.add(t, point, yaw, !closing);
                previous = point;
            }
            t += 0.1;
            track.add(t, previous, yaw);
            t += 0.35;
            track.add(t, previous + Eigen::Vector3d(0, 0, 30.0), yaw);
            t += 0.6;
        }
        track.add(t, stage_.offstage(track.last().pad.x()), kUserYawDeg);
        return track;
    }
};

// Fingers passing over the display at heights from 2 to 40 mm, never touching: false-accept material.
class HoverScenario final : public PointingScenario {
public:
    HoverScenario(const ScenarioContext& context, int passes)
        : PointingScenario(context, 3, ContentKind::Ui), passes_(passes) {}

private:
    Track buildTrack(long cycle) const override {
        cv::RNG rng = cycleRng(seed_, id_, cycle);
        std::vector<double> heights{2.0, 3.0, 5.0, 8.0, 12.0, 20.0, 30.0, 40.0};
        for (size_t i = heights.size(); i > 1; --i)
            std::swap(heights[i - 1], heights[rng.uniform(0, static_cast<int>(i))]);
        const cv::Size display = stage_.displaySize();
        Track track;
        double t = 0.0;
        for (int pass = 0; pass < passes_; ++pass) {
            const double height = heights[pass % heights.size()];
            const double y0 = rng.uniform(0.15, 0.85) * display.height,
                         y1 = rng.uniform(0.15, 0.85) * display.height;
            const bool leftToRight = rng.uniform(0, 2) == 0;
            const double x0 = (leftToRight ? 0.12 : 0.88) * display.width,
                         x1 = (leftToRight ? 0.88 : 0.12) * display.width;
            const Eigen::Vector3d from = stage_.onTable({x0, y0}, height),
                                  to = stage_.onTable({x1, y1}, height);
            const double yaw = kUserYawDeg + rng.gaussian(8.0);
            if (pass == 0) {
                track.add(t, stage_.offstage(from.x()), kUserYawDeg);
                t += kEnterSeconds;
            } else {
                const Eigen::Vector3d lifted = track.last().pad + Eigen::Vector3d(0, 0, 15.0);
                t += 0.3;
                track.add(t, lifted, track.last().yawDeg);
                t += 0.5;
                track.add(t, from + Eigen::Vector3d(0, 0, 15.0), yaw);
                t += 0.3;
            }
            track.add(t, from, yaw, true);
            t += (to - from).norm() / rng.uniform(80.0, 160.0);
            track.add(t, to, yaw);
        }
        t += kEnterSeconds;
        track.add(t, stage_.offstage(track.last().pad.x()), kUserYawDeg);
        return track;
    }

    int passes_;
};

// A hand placed by its wrist with fingers reaching for targets: multitouch gestures and a resting palm.
HandPose relaxedHand(const Eigen::Vector3d& wrist, double yawDeg, double pitchDeg, bool left, double scale) {
    HandPose pose;
    pose.scale = scale;
    pose.left = left;
    pose.forearmElevationDeg = 12.0;
    for (int f = 0; f < kFingerCount; ++f)
        pose.fingers[f] = relaxedJoints(static_cast<Finger>(f));
    pose.place(wrist, yawDeg, pitchDeg);
    return pose;
}

// Wrist position that puts the hand's middle fingertip near `middlePad` at rest.
Eigen::Vector3d wristFor(const HandPose& rest, const Eigen::Vector3d& middlePad) {
    return rest.wristToTable.translation() + middlePad - fingerPad(rest, Finger::Middle);
}

// Two- to ten-finger gestures: pinch, spread, rotate, and two spreading hands.
class MultitouchScenario final : public Scenario {
public:
    explicit MultitouchScenario(const ScenarioContext& context) : stage_(context), seed_(context.seed) {}

    double cycleSeconds() const override { return kGestures * kGestureSeconds; }

    SceneState at(double seconds) const override {
        const long total = static_cast<long>(std::floor(seconds / kGestureSeconds));
        const long cycle = total / kGestures;
        const int gesture = static_cast<int>(total % kGestures);
        const double local = seconds - total * kGestureSeconds;
        cv::RNG rng = cycleRng(seed_, 4, total);
        SceneState state;
        state.content = ContentKind::Photo;
        state.contentVariant = static_cast<int>(cycle);
        // Phases: enter, lower, gesture, lift, leave.
        const double enter = smootherStep(local / 0.9);
        const double lower = smootherStep((local - 0.9) / 0.4);
        const double act = smootherStep((local - 1.3) / 2.6);
        const double lift = smootherStep((local - 3.9) / 0.35);
        const double leave = smootherStep((local - 4.25) / 0.75);
        const double height = 25.0 * (1.0 - lower) + 25.0 * lift;
        const Eigen::Vector3d away = stage_.offstage(0.0) - stage_.centre();
        const Eigen::Vector3d offset = away * ((1.0 - enter) + leave);
        const Eigen::Vector3d centre =
            stage_.centre() + Eigen::Vector3d(rng.uniform(-40.0, 40.0), rng.uniform(-25.0, 25.0), 0.0);
        const double yaw = kUserYawDeg + rng.gaussian(8.0);
        switch (gesture) {
            case 0:  // pinch: thumb and index close in
                state.hands.push_back(gestureHand(centre, yaw, false, {Finger::Thumb, Finger::Index},
                                                  1.1 - 0.55 * act, 0.0, height, offset));
                break;
            case 1:  // spread: five fingers move apart
                state.hands.push_back(
                    gestureHand(centre, yaw, false,
                                {Finger::Thumb, Finger::Index, Finger::Middle, Finger::Ring, Finger::Little},
                                0.8 + 0.4 * act, 0.0, height, offset));
                break;
            case 2:  // rotate: thumb and index turn about their midpoint
                state.hands.push_back(gestureHand(centre, yaw, false, {Finger::Thumb, Finger::Index}, 1.0,
                                                  55.0 * act, height, offset));
                break;
            default: {  // ten fingers: two hands spreading and moving apart
                const std::vector<Finger> all{Finger::Thumb, Finger::Index, Finger::Middle, Finger::Ring,
                                              Finger::Little};
                const Eigen::Vector3d apart(55.0 + 25.0 * act, 0.0, 0.0);
                state.hands.push_back(gestureHand(stage_.centre() - apart, kUserYawDeg + 12.0, false, all,
                                                  0.85 + 0.3 * act, 0.0, height, offset));
                state.hands.push_back(gestureHand(stage_.centre() + apart, kUserYawDeg - 12.0, true, all,
                                                  0.85 + 0.3 * act, 0.0, height, offset));
                break;
            }
        }
        return state;
    }

private:
    static constexpr int kGestures = 4;
    static constexpr double kGestureSeconds = 5.0;

    // A hand whose `fingers` rest at their natural spread around `centre`, scaled about their centroid by
    // `spread` and turned about it by `turnDeg`, at `heightMm` above the table; the rest curl up.
    HandPose gestureHand(const Eigen::Vector3d& centre, double yawDeg, bool left,
                         const std::vector<Finger>& fingers, double spread, double turnDeg, double heightMm,
                         const Eigen::Vector3d& offset) const {
        HandPose pose = relaxedHand(Eigen::Vector3d::Zero(), yawDeg, 8.0, left, stage_.handScale());
        pose.place(wristFor(pose, centre), yawDeg, 8.0);
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        std::vector<Eigen::Vector3d> natural;
        for (Finger finger : fingers) {
            natural.push_back(fingerPad(pose, finger));
            centroid += natural.back();
        }
        centroid /= static_cast<double>(fingers.size());
        centroid.z() = 0.0;
        // Lower the hand so the fingers reach the table with a natural bend.
        double meanHeight = 0.0;
        for (const Eigen::Vector3d& pad : natural)
            meanHeight += pad.z();
        meanHeight /= static_cast<double>(natural.size());
        const Eigen::AngleAxisd turn(turnDeg * M_PI / 180.0, Eigen::Vector3d::UnitZ());
        for (int f = 0; f < kFingerCount; ++f)
            pose.fingers[f] = curledJoints(static_cast<Finger>(f));
        std::array<bool, kFingerCount> acting{};
        for (Finger finger : fingers) {
            acting[static_cast<int>(finger)] = true;
            pose.fingers[static_cast<int>(finger)] = relaxedJoints(finger);
        }
        // Keep the palm and the curled fingers clear of the table; the acting fingers reach down to it.
        double lowestRest = 1e9;
        const HandModel model = buildHand(pose);
        for (size_t i = 0; i < model.capsules.size(); ++i) {
            const int finger =
                i < 4 ? -1 : static_cast<int>(i - 4) / 3;  // forearm, palm, knuckles, thenar first
            if (finger < 0 || !acting[finger])
                lowestRest =
                    std::min(lowestRest, model.capsules[i].shape.supportPoint(-Eigen::Vector3d::UnitZ()).z());
        }
        constexpr double kClearanceMm = 6.0;
        Eigen::Isometry3d wrist = pose.wristToTable;
        wrist.translation().z() +=
            heightMm + std::max(kClearanceMm - (lowestRest - meanHeight), -4.0) - meanHeight;
        wrist = Eigen::Translation3d(centroid + offset) * turn * Eigen::Translation3d(-centroid) * wrist;
        pose.wristToTable = wrist;
        for (size_t i = 0; i < fingers.size(); ++i) {
            const int f = static_cast<int>(fingers[i]);
            pose.presented[f] = true;
            Eigen::Vector3d target = centroid + turn * (natural[i] - centroid) * spread;
            target.z() = heightMm;
            reachPad(pose, fingers[i], target + offset);
        }
        return pose;
    }

    Stage stage_;
    std::uint64_t seed_;
};

// A palm resting on the table while the index finger taps; the other fingers rest just above the table.
class PalmScenario final : public Scenario {
public:
    PalmScenario(const ScenarioContext& context, int taps)
        : stage_(context), seed_(context.seed), taps_(taps) {}

    double cycleSeconds() const override { return 2 * kMoveSeconds + taps_ * kTapSeconds; }

    SceneState at(double seconds) const override {
        const long cycle = static_cast<long>(std::floor(seconds / cycleSeconds()));
        const double local = seconds - cycle * cycleSeconds();
        cv::RNG rng = cycleRng(seed_, 5, cycle);
        SceneState state;
        state.content = ContentKind::Text;
        state.contentVariant = static_cast<int>(cycle);
        const double yaw = kUserYawDeg + rng.gaussian(6.0);
        const Eigen::Vector3d where =
            stage_.centre() + Eigen::Vector3d(rng.uniform(-50.0, 50.0), rng.uniform(0.0, 40.0), 0.0);
        HandPose pose = relaxedHand(Eigen::Vector3d::Zero(), yaw, -4.0, false, stage_.handScale());
        pose.place(wristFor(pose, where), yaw, -4.0);
        // Rest the hand: the lowest point of palm, thenar, knuckles and wrist touches the table.
        double lowest = 1e9;
        for (const HandCapsule& capsule : buildHand(pose).capsules)
            if (capsule.part != HandPart::Bone && capsule.part != HandPart::Fingertip)
                lowest = std::min(lowest, capsule.shape.supportPoint(-Eigen::Vector3d::UnitZ()).z());
        pose.wristToTable.translation().z() -= lowest;
        std::array<Eigen::Vector3d, kFingerCount> natural;
        for (int f = 0; f < kFingerCount; ++f)
            natural[f] = fingerPad(pose, static_cast<Finger>(f));
        // The hand comes in and leaves as a whole.
        const double total = cycleSeconds();
        const double in = smootherStep(local / kMoveSeconds),
                     out = smootherStep((local - (total - kMoveSeconds)) / kMoveSeconds);
        const Eigen::Vector3d offset = (stage_.offstage(0.0) - stage_.centre()) * ((1.0 - in) + out);
        pose.wristToTable.translation() += offset;
        // Index height: taps within the resting phase.
        const double tapping = local - kMoveSeconds;
        double indexHeight = 15.0;
        Eigen::Vector3d tapOffset = Eigen::Vector3d::Zero();
        if (tapping >= 0.0 && tapping < taps_ * kTapSeconds) {
            const int tap = static_cast<int>(tapping / kTapSeconds);
            const double phase = tapping - tap * kTapSeconds;
            cv::RNG tapRng = cycleRng(seed_, 50 + tap, cycle);
            tapOffset = Eigen::Vector3d(tapRng.uniform(-8.0, 8.0), tapRng.uniform(-12.0, 4.0), 0.0);
            // Up at 15 mm, down in 0.18 s, dwell 0.25 s, up in 0.25 s.
            indexHeight = 15.0 * (1.0 - smootherStep((phase - 0.3) / 0.18)) +
                          15.0 * smootherStep((phase - 0.73) / 0.25);
        }
        for (int f = 0; f < kFingerCount; ++f) {
            pose.presented[f] = true;
            Eigen::Vector3d target = natural[f] + offset;
            if (f == static_cast<int>(Finger::Index)) {
                target += tapOffset;
                target.z() = indexHeight + offset.z();
            } else {
                target.z() = std::max(natural[f].z(), 3.0 + f) + offset.z();
            }
            reachPad(pose, static_cast<Finger>(f), target);
        }
        state.hands.push_back(pose);
        return state;
    }

private:
    static constexpr double kMoveSeconds = 1.5;
    static constexpr double kTapSeconds = 1.2;

    Stage stage_;
    std::uint64_t seed_;
    int taps_;
};

// Nobody at the table; the content changes now and then.
class IdleScenario final : public Scenario {
public:
    explicit IdleScenario(int contents) : contents_(contents) {}
    double cycleSeconds() const override { return contents_ * kContentSeconds; }
    SceneState at(double seconds) const override {
        const long step = static_cast<long>(std::floor(seconds / kContentSeconds));
        static constexpr std::array<ContentKind, 3> kinds{ContentKind::Photo, ContentKind::Ui,
                                                          ContentKind::Text};
        SceneState state;
        state.content = kinds[step % kinds.size()];
        state.contentVariant = static_cast<int>(step / static_cast<long>(kinds.size()));
        return state;
    }

private:
    static constexpr double kContentSeconds = 8.0;
    int contents_;
};

// The README's show: a part of every scenario in turn.
class DemoScenario final : public Scenario {
public:
    explicit DemoScenario(const ScenarioContext& context) {
        parts_.push_back(std::make_unique<Grid35Scenario>(context, 8));
        parts_.push_back(std::make_unique<DragScenario>(context));
        parts_.push_back(std::make_unique<MultitouchScenario>(context));
        parts_.push_back(std::make_unique<HoverScenario>(context, 3));
        parts_.push_back(std::make_unique<PalmScenario>(context, 5));
        parts_.push_back(std::make_unique<IdleScenario>(1));
    }

    double cycleSeconds() const override {
        double total = 0.0;
        for (const auto& part : parts_)
            total += part->cycleSeconds();
        return total;
    }

    SceneState at(double seconds) const override {
        const double cycle = cycleSeconds();
        const long index = static_cast<long>(std::floor(seconds / cycle));
        double local = seconds - index * cycle;
        for (const auto& part : parts_) {
            if (local < part->cycleSeconds() || &part == &parts_.back()) {
                // Each demo cycle plays the parts' cycle of the same number, so repetitions differ.
                SceneState state = part->at(index * part->cycleSeconds() + local);
                return state;
            }
            local -= part->cycleSeconds();
        }
        return {};
    }

private:
    std::vector<std::unique_ptr<Scenario>> parts_;
};

}  // namespace

const std::vector<std::string>& scenarioNames() {
    static const std::vector<std::string> names{"grid35", "drag", "multitouch",  "hover",           "palm",
                                                "idle",   "demo", "table-setup", "pair-calibration"};
    return names;
}

std::unique_ptr<Scenario> makeScenario(std::string_view name, const ScenarioContext& context) {
    if (name == "grid35")
        return std::make_unique<Grid35Scenario>(context, 35);
    if (name == "drag")
        return std::make_unique<DragScenario>(context);
    if (name == "multitouch")
        return std::make_unique<MultitouchScenario>(context);
    if (name == "hover")
        return std::make_unique<HoverScenario>(context, 8);
    if (name == "palm")
        return std::make_unique<PalmScenario>(context, 8);
    if (name == "idle")
        return std::make_unique<IdleScenario>(3);
    if (name == "demo")
        return std::make_unique<DemoScenario>(context);
    if (name == "table-setup")
        return std::make_unique<TableSetupScenario>(context);
    if (name == "pair-calibration")
        return std::make_unique<PairCalibrationScenario>(context);
    std::string known;
    for (const std::string& scenario : scenarioNames())
        known += (known.empty() ? "" : ", ") + scenario;
    throw std::invalid_argument("unknown scenario \"" + std::string(name) + "\"; known scenarios: " + known);
}

}  // namespace everytouch::sim
