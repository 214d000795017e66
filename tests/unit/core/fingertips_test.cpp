#include "core/fingertips.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/geometry.h"
#include "sim/rig_geometry.h"
#include "sim/simulator.h"
#include "support/allocation_counter.h"

namespace everytouch::core {
namespace {

// A shape drawn into a mask the way a camera samples it: a pixel is inside when its centre is.
struct Capsule {
    Eigen::Vector2d from, to;  // the axis, base to tip
    double radius;

    // The end of the silhouette: the far end of the axis, a radius on.
    Eigen::Vector2d tip() const { return to + radius * (to - from).normalized(); }
};

void fillCapsule(cv::Mat& mask, const Capsule& capsule) {
    const Eigen::Vector2d axis = capsule.to - capsule.from;
    for (int y = 0; y < mask.rows; ++y)
        for (int x = 0; x < mask.cols; ++x) {
            const Eigen::Vector2d p(x, y);
            const double s = std::clamp((p - capsule.from).dot(axis) / axis.squaredNorm(), 0.0, 1.0);
            if ((p - capsule.from - s * axis).norm() <= capsule.radius)
                mask.at<uchar>(y, x) = 255;
        }
}

void fillEllipse(cv::Mat& mask, const Eigen::Vector2d& centre, double semiX, double semiY) {
    for (int y = 0; y < mask.rows; ++y)
        for (int x = 0; x < mask.cols; ++x) {
            const double u = (x - centre.x()) / semiX, v = (y - centre.y()) / semiY;
            if (u * u + v * v <= 1.0)
                mask.at<uchar>(y, x) = 255;
        }
}

Eigen::Vector2d towards(double degrees) {
    const double radians = degrees * M_PI / 180.0;
    return {std::cos(radians), std::sin(radians)};
}

constexpr double kFingerWidthPx = 20.0;  // finger width of the drawn hands, pixels

FingertipOptions drawnOptions() {
    FingertipOptions options;
    options.fingerWidthPx = kFingerWidthPx;
    return options;
}

// A right hand seen from above, fingers pointing down the image, the forearm reaching beyond the top edge.
// `mirror` draws a left hand; `fingers` of them point out, the others are curled into a fist.
std::vector<Capsule> drawHand(cv::Mat& mask, const Eigen::Vector2d& wrist, bool mirror, int fingers = 5) {
    const double side = mirror ? -1.0 : 1.0;
    auto at = [&](double x, double y) { return Eigen::Vector2d(wrist.x() + side * x, wrist.y() + y); };
    fillCapsule(mask, {at(0, 0), at(-25, -400), 30.0});
    fillEllipse(mask, at(0, 45), 46.0, 45.0);
    // Thumb, index, middle, ring, little: base, direction (degrees from +x, for a right hand) and length.
    struct Finger {
        double baseX, baseY, directionDeg, length, width;
    };
    const Finger shapes[5] = {{-40, 50, 135, 60, 22},
                              {-28, 80, 100, 70, 20},
                              {-8, 85, 91, 78, 20},
                              {12, 83, 82, 72, 19},
                              {32, 74, 72, 56, 17}};
    std::vector<Capsule> tips;
    for (int f = 0; f < 5; ++f) {
        const Finger& s = shapes[f];
        Eigen::Vector2d direction = towards(s.directionDeg);
        direction.x() *= side;
        const Eigen::Vector2d base = at(s.baseX, s.baseY);
        if (f < fingers) {
            const Capsule finger{base, base + s.length * direction, s.width / 2.0};
            fillCapsule(mask, finger);
            tips.push_back(finger);
        } else {
            // Curled: a knuckle bulging a little from the fist.
            fillCapsule(mask, {base, base + 4.0 * direction, s.width / 2.0});
        }
    }
    return tips;
}

std::string describe(const Fingertips& found) {
    std::ostringstream text;
    for (const Fingertip& f : found)
        text << "\n  tip " << f.tip.transpose() << " direction " << f.direction.transpose() << " width "
             << f.widthPx << " angle " << f.angleRad * 180.0 / M_PI << " hand " << f.hand;
    return text.str();
}

// The found fingertip nearest to `tip`, or null.
const Fingertip* nearest(const Fingertips& found, const Eigen::Vector2d& tip) {
    const Fingertip* best = nullptr;
    for (const Fingertip& f : found)
        if (!best || (f.tip - tip).norm() < (best->tip - tip).norm())
            best = &f;
    return best;
}

void expectFound(const Fingertips& found, const Capsule& finger, int hand) {
    const Fingertip* f = nearest(found, finger.tip());
    ASSERT_NE(f, nullptr);
    EXPECT_LT((f->tip - finger.tip()).norm(), 0.75)
        << "tip at " << finger.tip().transpose() << describe(found);
    const Eigen::Vector2d axis = (finger.to - finger.from).normalized();
    EXPECT_GT(f->direction.dot(axis), std::cos(8.0 * M_PI / 180.0)) << "tip at " << finger.tip().transpose();
    EXPECT_NEAR(f->widthPx, 2.0 * finger.radius, 0.15 * 2.0 * finger.radius);
    EXPECT_LT(f->angleRad, M_PI / 2.0);
    EXPECT_EQ(f->hand, hand);
}

TEST(Fingertips, FindsTheFiveFingersOfAnOpenHand) {
    cv::Mat mask = cv::Mat::zeros(488, 648, CV_8UC1);
    const std::vector<Capsule> fingers = drawHand(mask, {320, 150}, false);
    FingertipScratch scratch;
    Fingertips found;
    findFingertips(mask, drawnOptions(), scratch, found);
    ASSERT_EQ(found.size(), 5u) << describe(found);
    for (const Capsule& finger : fingers)
        expectFound(found, finger, 0);
}

TEST(Fingertips, AFistHasNone) {
    cv::Mat mask = cv::Mat::zeros(488, 648, CV_8UC1);
    drawHand(mask, {320, 150}, false, 0);
    FingertipScratch scratch;
    Fingertips found;
    findFingertips(mask, drawnOptions(), scratch, found);
    EXPECT_TRUE(found.empty()) << describe(found);
}

TEST(Fingertips, AFistWithAPointingIndexHasOne) {
    cv::Mat mask = cv::Mat::zeros(488, 648, CV_8UC1);
    const std::vector<Capsule> fingers = drawHand(mask, {320, 150}, false, 2);
    // The thumb tucked in too: only the index stands out.
    cv::Mat fist = cv::Mat::zeros(mask.size(), CV_8UC1);
    drawHand(fist, {320, 150}, false, 0);
    fillCapsule(fist, fingers[1]);
    FingertipScratch scratch;
    Fingertips found;
    findFingertips(fist, drawnOptions(), scratch, found);
    ASSERT_EQ(found.size(), 1u) << describe(found);
    expectFound(found, fingers[1], 0);
}

TEST(Fingertips, AFingerPointingDownIsAShortStub) {
    // From above, a finger pointing at the table shows as a stub standing about a finger width beyond the
    // knuckles.
    cv::Mat mask = cv::Mat::zeros(488, 648, CV_8UC1);
    drawHand(mask, {320, 150}, false, 0);
    const Eigen::Vector2d base(312, 235);  // the middle finger's knuckle
    const Capsule stub{base, base + Eigen::Vector2d(0, 20), 10.0};
    fillCapsule(mask, stub);
    FingertipScratch scratch;
    Fingertips found;
    findFingertips(mask, drawnOptions(), scratch, found);
    ASSERT_EQ(found.size(), 1u) << describe(found);
    expectFound(found, stub, 0);
}

TEST(Fingertips, TwoHandsShowTenFingers) {
    cv::Mat mask = cv::Mat::zeros(488, 648, CV_8UC1);
    const std::vector<Capsule> left = drawHand(mask, {180, 140}, true);
    const std::vector<Capsule> right = drawHand(mask, {470, 160}, false);
    FingertipScratch scratch;
    Fingertips found;
    findFingertips(mask, drawnOptions(), scratch, found);
    ASSERT_EQ(found.size(), 10u) << describe(found);
    for (const Capsule& finger : left)
        expectFound(found, finger, 0);
    for (const Capsule& finger : right)
        expectFound(found, finger, 1);

    FingertipOptions fewer = drawnOptions();
    fewer.maxFingertips = 4;
    Fingertips sharpest;
    findFingertips(mask, fewer, scratch, sharpest);
    ASSERT_EQ(sharpest.size(), 4u) << describe(sharpest);
    std::vector<double> angles;
    for (const Fingertip& f : found)
        angles.push_back(f.angleRad);
    std::sort(angles.begin(), angles.end());
    for (const Fingertip& f : sharpest)
        EXPECT_LE(f.angleRad, angles[3]);
}

TEST(Fingertips, TheImageEdgeMakesNoFingertip) {
    cv::Mat mask = cv::Mat::zeros(488, 648, CV_8UC1);
    // Forearms crossing the top edge at 30 degrees and the left edge at 10, each making an acute corner with
    // the edge; a hand whose finger runs beyond the bottom edge.
    fillCapsule(mask, {{200, 200}, Eigen::Vector2d(200, 200) + 400 * towards(-30), 28});
    fillCapsule(mask, {{150, 300}, Eigen::Vector2d(150, 300) + 400 * towards(170), 28});
    fillEllipse(mask, {450, 400}, 40, 30);
    fillCapsule(mask, {{450, 400}, {470, 540}, 10});
    // A hand whose finger ends just inside the right edge still shows that fingertip.
    fillEllipse(mask, {520, 250}, 35, 30);
    const Capsule finger{{520, 250}, {630, 240}, 9};
    fillCapsule(mask, finger);
    FingertipScratch scratch;
    Fingertips found;
    findFingertips(mask, drawnOptions(), scratch, found);
    ASSERT_EQ(found.size(), 1u) << describe(found);
    expectFound(found, finger, 1);
}

// A display judged from y = 100 down, and a hand inside it whose forearm leaves it upwards at `armDegrees`.
struct ArmLeavingTheDisplay {
    cv::Mat judged = cv::Mat::zeros(488, 648, CV_8UC1);
    cv::Mat mask = cv::Mat::zeros(488, 648, CV_8UC1);
    Capsule finger{{300, 170}, {310, 300}, 9};

    explicit ArmLeavingTheDisplay(double armDegrees) {
        judged(cv::Rect(40, 100, 560, 360)).setTo(255);
        fillCapsule(mask, {{300, 150}, Eigen::Vector2d(300, 150) + 300 * towards(armDegrees), 30});
        fillEllipse(mask, {300, 170}, 40, 32);
        fillCapsule(mask, finger);
    }
};

TEST(Fingertips, TheEdgeOfWhatWasJudgedCutsLikeTheImageEdge) {
    // A segmentation that judges only the display cuts a forearm at the display's edge: the corners of that
    // cut are no fingertips, the finger inside the display is.
    ArmLeavingTheDisplay scene(-60);
    scene.mask.setTo(0, scene.judged == 0);
    FingertipScratch scratch;
    Fingertips found;
    findFingertips(scene.mask, drawnOptions(), scratch, found);
    EXPECT_GT(found.size(), 1u) << "without the judged region the cut's corners look like fingertips";
    findFingertips(scene.mask, drawnOptions(), scratch, found, scene.judged);
    ASSERT_EQ(found.size(), 1u) << describe(found);
    expectFound(found, scene.finger, 0);
    EXPECT_THROW(
        findFingertips(scene.mask, drawnOptions(), scratch, found, scene.judged(cv::Rect(0, 0, 10, 10))),
        std::invalid_argument);
}

TEST(Fingertips, ACornerRoundedOffNearTheJudgedEdgeIsNoFingertip) {
    // The mask's smoothing rounds the corners where the judged region's edge cuts a forearm, and may leave
    // them a few pixels inside that edge: still corners, not fingertips.
    ArmLeavingTheDisplay scene(-150);
    scene.mask(cv::Rect(0, 0, scene.mask.cols, 104)).setTo(0);
    cv::medianBlur(scene.mask, scene.mask, 11);
    FingertipScratch scratch;
    Fingertips found;
    FingertipOptions onTheEdgeOnly = drawnOptions();
    onTheEdgeOnly.edgeMarginWidths = 0.0;
    findFingertips(scene.mask, onTheEdgeOnly, scratch, found, scene.judged);
    EXPECT_GT(found.size(), 1u) << "the rounded corners off the edge look like fingertips";
    findFingertips(scene.mask, drawnOptions(), scratch, found, scene.judged);
    ASSERT_EQ(found.size(), 1u) << describe(found);
    expectFound(found, scene.finger, 0);
}

TEST(Fingertips, AFingerTouchingNearTheJudgedEdgeShowsItsEndAlone) {
    // A button at the display's near side: the hand stays outside the display, the finger reaches in by
    // 1.6-2 widths, and only that end is judged. A speck of that size inside the display is no finger.
    for (const double reach : {1.6, 2.0}) {
        ArmLeavingTheDisplay scene(-90);
        const Capsule finger{{300, 60}, {300, 100 + reach * kFingerWidthPx - 9}, 9};
        scene.mask.setTo(0);
        fillEllipse(scene.mask, {300, 40}, 40, 32);
        fillCapsule(scene.mask, finger);
        scene.mask.setTo(0, scene.judged == 0);
        fillEllipse(scene.mask, {450, 300}, 10, 18);  // 1.4 widths squared, inside
        FingertipScratch scratch;
        Fingertips found;
        findFingertips(scene.mask, drawnOptions(), scratch, found, scene.judged);
        ASSERT_EQ(found.size(), 1u) << "reaching in " << reach << " widths" << describe(found);
        expectFound(found, finger, 0);
    }
}

TEST(Fingertips, AllocateNothingOnceWarm) {
    cv::Mat twoHands = cv::Mat::zeros(488, 648, CV_8UC1), oneHand = cv::Mat::zeros(488, 648, CV_8UC1);
    drawHand(twoHands, {180, 140}, true);
    drawHand(twoHands, {470, 160}, false);
    drawHand(oneHand, {300, 170}, false, 2);
    cv::Mat none = cv::Mat::zeros(488, 648, CV_8UC1);
    FingertipScratch scratch;
    Fingertips found;
    const std::uint64_t cold = test::allocationCount();
    findFingertips(twoHands, drawnOptions(), scratch, found);
    EXPECT_GT(test::allocationCount() - cold, 0u) << "the first frame sizes the buffers";
    const std::uint64_t before = test::allocationCount();
    for (cv::Mat* mask : {&oneHand, &none, &twoHands, &oneHand})
        findFingertips(*mask, drawnOptions(), scratch, found);
    EXPECT_EQ(test::allocationCount() - before, 0u);
    EXPECT_EQ(found.size(), 2u);
}

TEST(Fingertips, NoHandNoFingertip) {
    const cv::Mat mask = cv::Mat::zeros(488, 648, CV_8UC1);
    FingertipScratch scratch;
    Fingertips found{Fingertip{}};
    findFingertips(mask, drawnOptions(), scratch, found);
    EXPECT_TRUE(found.empty()) << describe(found);
}

// The simulated rig's hand masks (the segmentation's truth) against its fingers. The truth's contact point
// is the pad's foot on the table; for a hovering finger the pad itself is compared, as the camera sees it at
// its height.
struct Error {
    double sum = 0.0;
    int count = 0;
    void add(double e) { sum += e, ++count; }
    double mean() const { return count ? sum / count : 0.0; }
};

// Least squares for the pad model: silhouette end - pad = back * widthPx * direction + height * up, where
// `up` is the image's shift per millimetre of height at the pad.
struct PadFit {
    Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
    Eigen::Vector2d right = Eigen::Vector2d::Zero();
    void add(const Eigen::Vector2d& offset, const Fingertip& tip, const Eigen::Vector2d& up) {
        Eigen::Matrix2d basis;  // columns: the two terms' directions
        basis << tip.widthPx * tip.direction, up;
        normal += basis.transpose() * basis;
        right += basis.transpose() * offset;
    }
    void add(const PadFit& other) { normal += other.normal, right += other.right; }
    Eigen::Vector2d solve() const { return normal.ldlt().solve(right); }  // back (widths), height (mm)
};

struct SceneScore {
    int frames = 0;
    int inImage = 0, inImageFound = 0;  // presented fingers whose contact point lies in the image
    int visible = 0, visibleFound = 0;  // ... whose pad is seen away from the image's edge and other fingers
    int falsePositives = 0;             // fingertips where no presented finger is
    Error touching, touchingThumbs, hovering, hoveringThumbs;  // pad error of found fingers, pixels
    PadFit fingers, thumbs;                                    // touching ones
};

SceneScore scoreScenario(const std::string& name, std::uint64_t seed, int samples) {
    sim::SimParameters parameters;
    parameters.scenario = name;
    parameters.seed = seed;
    cv::Mat pattern(parameters.projectorSize, CV_8UC1);
    cv::RNG(static_cast<unsigned>(seed)).fill(pattern, cv::RNG::UNIFORM, 0, 2);
    sim::Simulator simulator(parameters, pattern);
    const Calibration& calibration = simulator.calibration();
    const FingertipOptions options = rigFingertipOptions(calibration);
    // A found fingertip is a finger's when within a finger width of its pad: the pads of two fingers side by
    // side are a finger width apart.
    const double radius = options.fingerWidthPx;
    // A fingertip shows when the finger is seen for a step of contour behind its end.
    const double margin = options.stepWidths * options.fingerWidthPx;
    const cv::Rect2d image(0, 0, parameters.cameraSize.width, parameters.cameraSize.height);
    const cv::Rect2d inner(margin, margin, image.width - 2 * margin, image.height - 2 * margin);

    SceneScore score;
    FingertipScratch scratch;
    Fingertips found;
    core::Frame frame;
    sim::FrameTruth truth;
    const double cycle = simulator.scenario().cycleSeconds();
    for (int i = 0; i < samples; ++i) {
        const auto index = static_cast<std::uint64_t>(cycle * (i + 0.5) / samples * parameters.frameRate);
        simulator.render(index, frame, truth);
        findFingertips(truth.handMask, options, scratch, found);
        ++score.frames;
        std::vector<Eigen::Vector2d> pads;
        for (const sim::FingertipTruth& finger : truth.fingertips)
            pads.push_back(projectPoint(calibration.cameraMatrix, calibration.tableToCamera, finger.pad));
        std::vector<bool> taken(found.size(), false);
        for (size_t f = 0; f < truth.fingertips.size(); ++f) {
            const sim::FingertipTruth& finger = truth.fingertips[f];
            if (!finger.presented)
                continue;
            int best = -1;
            for (size_t k = 0; k < found.size(); ++k)
                if (!taken[k] && (found[k].pad - pads[f]).norm() < radius &&
                    (best < 0 || (found[k].pad - pads[f]).norm() < (found[best].pad - pads[f]).norm()))
                    best = static_cast<int>(k);
            if (best >= 0)
                taken[best] = true;
            // Fingertips as wide as they come touch side by side when their pads are closer than that width:
            // one silhouette.
            const double apartPx = options.maxWidthRatio * options.fingerWidthPx;
            bool apart = true;
            for (size_t g = 0; g < truth.fingertips.size(); ++g)
                apart = apart &&
                        (g == f || !truth.fingertips[g].presented || (pads[g] - pads[f]).norm() >= apartPx);
            const bool inImage = image.contains({finger.camera.x, finger.camera.y});
            const bool visible = apart && inner.contains({pads[f].x(), pads[f].y()});
            score.inImage += inImage, score.inImageFound += inImage && best >= 0;
            score.visible += visible, score.visibleFound += visible && best >= 0;
            if (best < 0)
                continue;
            const double error = (found[best].pad - pads[f]).norm();
            const bool thumb = finger.finger == sim::Finger::Thumb;
            if (finger.touching) {
                const Eigen::Vector2d up = projectPoint(calibration.cameraMatrix, calibration.tableToCamera,
                                                        finger.pad + Eigen::Vector3d::UnitZ()) -
                                           pads[f];
                (thumb ? score.thumbs : score.fingers).add(found[best].tip - pads[f], found[best], up);
            }
            (finger.touching ? (thumb ? score.touchingThumbs : score.touching)
                             : (thumb ? score.hoveringThumbs : score.hovering))
                .add(error);
        }
        for (size_t k = 0; k < found.size(); ++k) {
            if (taken[k])
                continue;
            // A fingertip next to a presented finger but taken by a nearer one is no false one.
            bool nearPresented = false;
            for (size_t f = 0; f < truth.fingertips.size(); ++f)
                nearPresented = nearPresented ||
                                (truth.fingertips[f].presented && (found[k].pad - pads[f]).norm() < radius);
            score.falsePositives += !nearPresented;
        }
    }
    return score;
}

TEST(Fingertips, FindTheSimulatedFingersAndTheirPads) {
    struct Row {
        const char* scenario;
        int samples;
        SceneScore score;
    };
    std::vector<Row> rows{{"grid35", 160, {}},
                          {"drag", 120, {}},
                          {"multitouch", 160, {}},
                          {"palm", 120, {}},
                          {"hover", 120, {}}};
    Error touching;
    int falsePositives = 0, visible = 0;
    std::printf(
        "scenario    frames  in image found  visible found   FP    touch px (n)   thumbs px (n)  "
        "hover px (n)   thumbs px (n)\n");
    for (Row& row : rows) {
        row.score = scoreScenario(row.scenario, 1, row.samples);
        const SceneScore& s = row.score;
        std::printf("%-10s  %6d  %4d %.4f  %4d %.4f  %4d  %.2f (%4d)  %.2f (%4d)  %.2f (%4d)  %.2f (%4d)\n",
                    row.scenario, s.frames, s.inImage, double(s.inImageFound) / std::max(1, s.inImage),
                    s.visible, double(s.visibleFound) / std::max(1, s.visible), s.falsePositives,
                    s.touching.mean(), s.touching.count, s.touchingThumbs.mean(), s.touchingThumbs.count,
                    s.hovering.mean(), s.hovering.count, s.hoveringThumbs.mean(), s.hoveringThumbs.count);
        EXPECT_GE(s.visibleFound, 0.99 * s.visible) << row.scenario;
        EXPECT_LE(s.touching.mean(), 1.5) << row.scenario;
        EXPECT_LE(s.hovering.mean(), 1.5) << row.scenario;
        touching.sum += s.touching.sum + s.touchingThumbs.sum;
        touching.count += s.touching.count + s.touchingThumbs.count;
        falsePositives += s.falsePositives, visible += s.visible;
    }
    EXPECT_LE(touching.mean(), 1.5);
    // The pad model's defaults are what the touching fingers show (docs/fingertips.md).
    PadFit fingers, thumbs;
    for (const Row& row : rows)
        fingers.add(row.score.fingers), thumbs.add(row.score.thumbs);
    const Eigen::Vector2d fitted = fingers.solve(), fittedThumbs = thumbs.solve();
    std::printf(
        "pad behind the silhouette's end: fingers %.2f widths and %.1f mm down, thumbs %.2f and %.1f\n",
        fitted[0], fitted[1], fittedThumbs[0], fittedThumbs[1]);
    const FingertipOptions defaults;
    EXPECT_NEAR(fitted[0], defaults.padBackWidths, 0.05);
    EXPECT_NEAR(fitted[1], 4.0, 0.5);
    EXPECT_LE(falsePositives, 0.1 * visible);
    EXPECT_EQ(rows[3].score.falsePositives, 0) << "the resting palm";
}

TEST(Fingertips, RigOptionsFollowTheCalibration) {
    const Calibration calibration = sim::rigCalibration(sim::SimParameters{});
    const FingertipOptions options = rigFingertipOptions(calibration, 16.0, 4.0);
    // 16 mm of table at the image's centre, across and along.
    const Eigen::Vector2d centre(0.5 * (calibration.cameraSize.width - 1),
                                 0.5 * (calibration.cameraSize.height - 1));
    const Eigen::Vector2d table = applyHomography(calibration.tableToCameraHomography().inverse(), centre);
    auto image = [&](double x, double y, double z) {
        return projectPoint(calibration.cameraMatrix, calibration.tableToCamera, {x, y, z});
    };
    const double across = (image(table.x() + 8, table.y(), 0) - image(table.x() - 8, table.y(), 0)).norm();
    const double along = (image(table.x(), table.y() + 8, 0) - image(table.x(), table.y() - 8, 0)).norm();
    EXPECT_NEAR(options.fingerWidthPx, std::sqrt(across * along), 0.01 * options.fingerWidthPx);
    // A point 4 mm up drops onto the table point below it, anywhere in the image.
    for (const Eigen::Vector2d& corner : {Eigen::Vector2d(-120, -40), Eigen::Vector2d(130, 90)}) {
        const Eigen::Vector2d dropped = applyHomography(options.padDrop, image(corner.x(), corner.y(), 4.0));
        EXPECT_LT((dropped - image(corner.x(), corner.y(), 0.0)).norm(), 1e-6);
    }
}

TEST(Fingertips, OptionsNameWhatIsWrong) {
    EXPECT_EQ(FingertipOptions{}.validate(), std::nullopt);
    FingertipOptions options;
    options.fingerWidthPx = 0.0;
    ASSERT_TRUE(options.validate());
    EXPECT_NE(options.validate()->find("finger_width_px"), std::string::npos);
    options = {};
    options.stepWidths = 0.5;
    EXPECT_NE(options.validate()->find("step_widths"), std::string::npos);
    options = {};
    options.maxWidthRatio = 0.3;
    EXPECT_NE(options.validate()->find("max_width_ratio"), std::string::npos);
    FingertipScratch scratch;
    Fingertips found;
    EXPECT_THROW(findFingertips(cv::Mat::zeros(8, 8, CV_8UC1), options, scratch, found),
                 std::invalid_argument);
}

}  // namespace
}  // namespace everytouch::core
