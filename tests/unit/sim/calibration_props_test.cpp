// The simulated rig plays the calibration procedures: projector images, the card and the board as props, and
// the table-setup and pair-calibration scenarios, checked against the detectors the daemon calibrates with.
#include "sim/calibration_scenarios.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/geometry.h"
#include "core/projector_chessboard.h"
#include "core/table_rectangle.h"
#include "sim/rig_geometry.h"
#include "sim/simulator.h"
#include "support/random_pattern.h"

namespace everytouch::sim {
namespace {

Eigen::Vector2d project(const core::Calibration& calibration, const Eigen::Vector3d& point) {
    const Eigen::Vector3d q = calibration.cameraMatrix * (calibration.tableToCamera * point);
    return q.head<2>() / q.z();
}

// The camera frames of I and I' (frames `index` and `index` + 1, index even) and their mean, the texture.
struct FramePair {
    cv::Mat positive, negative, texture;
    FrameTruth truth;
};

FramePair renderPair(Simulator& simulator, std::uint64_t index) {
    FramePair pair;
    core::Frame frame;
    FrameTruth second;
    simulator.render(index, frame, pair.truth);
    pair.positive = frame.image.clone();
    simulator.render(index + 1, frame, second);
    pair.negative = frame.image.clone();
    cv::addWeighted(pair.positive, 0.5, pair.negative, 0.5, 0.0, pair.texture);
    return pair;
}

cv::Mat chessboardImage(cv::Size projectorSize) {
    cv::Mat image;
    core::renderProjectorChessboard(calibrationChessboard(), projectorSize, image);
    return image;
}

// Largest distance from a detected corner to the nearest of the true ones, camera pixels.
double worstCornerError(const std::array<Eigen::Vector2d, 4>& detected,
                        const std::array<Eigen::Vector2d, 4>& truth) {
    double worst = 0.0;
    for (const Eigen::Vector2d& corner : detected) {
        double nearest = 1e9;
        for (const Eigen::Vector2d& expected : truth)
            nearest = std::min(nearest, (corner - expected).norm());
        worst = std::max(worst, nearest);
    }
    return worst;
}

std::array<Eigen::Vector2d, 4> stripeInCamera(const core::Calibration& calibration, const CardProp& card) {
    std::array<Eigen::Vector2d, 4> corners;
    const std::array<Eigen::Vector3d, 4> table = stripeCorners(card);
    for (int i = 0; i < 4; ++i)
        corners[i] = project(calibration, table[i]);
    return corners;
}

cv::Point2d centroid(const cv::Mat& mask) {
    const cv::Moments m = cv::moments(mask, true);
    return {m.m10 / m.m00, m.m01 / m.m00};
}

TEST(ProjectImage, SquareLandsWhereTheTableHomographyPutsIt) {
    SimParameters p;
    p.scenario = "idle";
    p.content = "gray";
    Simulator simulator(p, test::randomPattern(p.projectorSize, 3));
    const core::Calibration& calibration = simulator.calibration();
    const cv::Rect square(300, 180, 80, 60);
    for (const bool whiteOnBlack : {true, false}) {
        cv::Mat image(p.projectorSize, CV_8UC1, cv::Scalar(whiteOnBlack ? 0 : 255));
        image(square).setTo(whiteOnBlack ? 255 : 0);
        simulator.projectImage(image);
        const FramePair pair = renderPair(simulator, 100);

        // Where the square's corners land on the table, in the camera (panel pixel centres at integers).
        const Eigen::Matrix3d toCamera = calibration.projectorToCameraHomography(0.0);
        std::vector<cv::Point> outline;
        std::vector<cv::Point2f> exactOutline;
        const double x0 = square.x - 0.5, y0 = square.y - 0.5, x1 = x0 + square.width,
                     y1 = y0 + square.height;
        for (const Eigen::Vector2d& corner : {Eigen::Vector2d(x0, y0), Eigen::Vector2d(x1, y0),
                                              Eigen::Vector2d(x1, y1), Eigen::Vector2d(x0, y1)}) {
            const Eigen::Vector2d c = core::applyHomography(toCamera, corner);
            exactOutline.emplace_back(static_cast<float>(c.x()), static_cast<float>(c.y()));
            outline.emplace_back(static_cast<int>(std::lround(c.x() * 256)),
                                 static_cast<int>(std::lround(c.y() * 256)));
        }
        cv::Mat expected = cv::Mat::zeros(p.cameraSize, CV_8UC1);
        cv::fillConvexPoly(expected, outline, cv::Scalar(255), cv::LINE_8, 8);
        const cv::Point2d expectedCentre = centroid(expected);
        const cv::Rect near = cv::boundingRect(expected) + cv::Size(40, 40) - cv::Point(20, 20);

        // Inside the square and a ring around it, away from its blurred edge.
        cv::Mat inside, around;
        cv::erode(expected, inside, cv::Mat(), cv::Point(-1, -1), 3);
        cv::dilate(expected, around, cv::Mat(), cv::Point(-1, -1), 8);
        cv::Mat ringFar;
        cv::dilate(expected, ringFar, cv::Mat(), cv::Point(-1, -1), 3);
        around.setTo(0, ringFar);
        for (const cv::Mat* frame : {&pair.positive, &pair.negative}) {
            cv::Mat gray, found;
            cv::cvtColor(*frame, gray, cv::COLOR_BGR2GRAY);
            const double mid = (cv::mean(gray, inside)[0] + cv::mean(gray, around)[0]) / 2.0;
            cv::threshold(gray(near), found, mid, 255,
                          whiteOnBlack ? cv::THRESH_BINARY : cv::THRESH_BINARY_INV);
            const cv::Point2d foundCentre = centroid(found) + cv::Point2d(near.tl());
            EXPECT_LT(cv::norm(foundCentre - expectedCentre), 0.5) << "white on black " << whiteOnBlack;
            const double area = cv::contourArea(exactOutline);
            EXPECT_NEAR(cv::countNonZero(found), area, 0.02 * area);
        }

        // The code is still embedded: C+ - C- inside the square follows the pattern seen through H_CP.
        cv::Mat difference, code;
        cv::Mat positive, negative;
        cv::cvtColor(pair.positive, positive, cv::COLOR_BGR2GRAY);
        cv::cvtColor(pair.negative, negative, cv::COLOR_BGR2GRAY);
        cv::subtract(positive, negative, difference, cv::noArray(), CV_32F);
        cv::Mat pattern;
        simulator.pattern().convertTo(pattern, CV_32F);
        Eigen::Matrix3d h = toCamera;
        cv::Mat hcv(3, 3, CV_64F);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                hcv.at<double>(r, c) = h(r, c);
        cv::warpPerspective(pattern, code, hcv, p.cameraSize, cv::INTER_LINEAR);
        // Where the projector shows white: on black the code is below the projector's gamma and black level.
        const cv::Mat& white = whiteOnBlack ? inside : around;
        cv::Scalar meanD, sdD, meanC, sdC;
        cv::meanStdDev(difference, meanD, sdD, white);
        cv::meanStdDev(code, meanC, sdC, white);
        cv::Mat product = (difference - meanD[0]).mul(code - meanC[0]);
        const double r = cv::mean(product, white)[0] / (sdD[0] * sdC[0]);
        EXPECT_GT(r, 0.3) << "white on black " << whiteOnBlack;
        EXPECT_GT(sdD[0], 2.0);
    }
}

TEST(ProjectImage, EmptyImageReturnsToTheContentAndWrongImagesAreRejected) {
    SimParameters p;
    p.scenario = "idle";
    p.content = "gray";
    Simulator plain(p, test::randomPattern(p.projectorSize, 3));
    Simulator projecting(p, test::randomPattern(p.projectorSize, 3));
    core::Frame a, b;
    FrameTruth truth;
    projecting.projectImage(cv::Mat(p.projectorSize, CV_8UC3, cv::Scalar(0, 0, 255)));
    projecting.render(10, b, truth);
    plain.render(10, a, truth);
    EXPECT_GT(cv::norm(a.image, b.image, cv::NORM_L1) / a.image.total(), 10.0);
    projecting.projectImage(cv::Mat());
    projecting.render(10, b, truth);
    EXPECT_EQ(cv::norm(a.image, b.image, cv::NORM_INF), 0.0);

    EXPECT_THROW(projecting.projectImage(cv::Mat(p.projectorSize.height, p.projectorSize.width + 1, CV_8UC1)),
                 std::invalid_argument);
    EXPECT_THROW(projecting.projectImage(cv::Mat(p.projectorSize, CV_32FC1)), std::invalid_argument);
    EXPECT_THROW(projecting.projectImage(cv::Mat(p.projectorSize, CV_8UC4)), std::invalid_argument);
}

TEST(TableSetupScenario, TheStripeIsFoundWhereTheCardLies) {
    for (const std::uint64_t seed : {1u, 7u}) {
        SimParameters p;
        p.scenario = "table-setup";
        p.seed = seed;
        Simulator simulator(p, test::randomPattern(p.projectorSize, 3));
        simulator.projectImage(chessboardImage(p.projectorSize));
        const FramePair pair = renderPair(simulator, 240);
        ASSERT_TRUE(pair.truth.props.card);
        EXPECT_FALSE(pair.truth.props.board);
        const CardProp& card = *pair.truth.props.card;
        EXPECT_NEAR(card.faceToTable.translation().z(), kCardThicknessMm, 1e-9);

        // Where a user lays it: clear of the chessboard, lit, in view.
        const CalibrationStage stage(simulator.calibration(), calibrationChessboard());
        EXPECT_GT(stage.clearance(card).least(), 5.0);

        const core::Result<core::TableRectangleDetection> stripe = core::findTableRectangle(pair.texture, {});
        ASSERT_TRUE(stripe.ok()) << stripe.failure().message;
        const double error = worstCornerError(stripe->corners, stripeInCamera(simulator.calibration(), card));
        RecordProperty("stripe_corner_error_px_seed" + std::to_string(seed), std::to_string(error));
        EXPECT_LT(error, 0.3);
        const core::Result<core::ChessboardDetection> chessboard =
            core::detectProjectedChessboard(pair.texture, calibrationChessboard(), p.projectorSize);
        EXPECT_TRUE(chessboard.ok()) << chessboard.failure().message;
    }
}

TEST(PairCalibrationScenario, PosesAreWhatTheCalibrationNeeds) {
    SimParameters p;
    p.scenario = "pair-calibration";
    const core::Calibration calibration = Simulator(p, test::randomPattern(p.projectorSize, 3)).calibration();
    for (const std::uint64_t seed : {1u, 2u, 3u}) {
        const PairCalibrationScenario scenario({calibration, seed, 1.0});
        const CalibrationStage stage(calibration, calibrationChessboard());
        const std::vector<PairCalibrationScenario::Pose>& poses = scenario.poses();
        ASSERT_EQ(poses.size(), 6u);
        EXPECT_FALSE(poses[0].board);
        std::vector<Eigen::Vector3d> normals{Eigen::Vector3d::UnitZ()};
        for (size_t k = 1; k < poses.size(); ++k) {
            const PairCalibrationScenario::Pose& pose = poses[k];
            ASSERT_TRUE(pose.board);
            EXPECT_GE(pose.tiltDeg, 12.0);
            EXPECT_LE(pose.tiltDeg, 30.0);
            EXPECT_GE(pose.liftMm, 40.0);
            EXPECT_LE(pose.liftMm, 80.0);
            EXPECT_GT(stage.clearance(pose.card).least(), 1.0) << "pose " << k << " seed " << seed;
            EXPECT_LE(stage.clearance(pose.card).cameraViewDeg, 50.0);
            // The card lies on the board.
            const Eigen::Isometry3d onBoard = pose.board->faceToTable.inverse() * pose.card.faceToTable;
            EXPECT_NEAR(onBoard.translation().z(), kCardThicknessMm, 1e-9);
            for (const Eigen::Vector3d& corner : cardCorners(pose.card)) {
                const Eigen::Vector3d local = pose.board->faceToTable.inverse() * corner;
                EXPECT_LT(std::abs(local.x()), pose.board->sizeMm.width / 2);
                EXPECT_LT(std::abs(local.y()), pose.board->sizeMm.height / 2);
            }
            // The board carries the whole chessboard and stays above the table.
            for (const Eigen::Vector3d& corner : stage.chessboardOn(pose.board->faceToTable)) {
                const Eigen::Vector3d local = pose.board->faceToTable.inverse() * corner;
                EXPECT_LT(std::abs(local.x()), pose.board->sizeMm.width / 2);
                EXPECT_LT(std::abs(local.y()), pose.board->sizeMm.height / 2);
            }
            for (const Eigen::Vector3d& corner : boardCorners(*pose.board))
                EXPECT_GE(corner.z(), -1e-9);
            normals.push_back(pose.board->faceToTable.linear().col(2));
        }
        for (size_t i = 0; i < normals.size(); ++i)
            for (size_t j = i + 1; j < normals.size(); ++j)
                EXPECT_GE(std::acos(std::min(1.0, normals[i].dot(normals[j]))) * 180.0 / M_PI,
                          PairCalibrationScenario::kMinTiltDifferenceDeg)
                    << "surfaces " << i << " and " << j << ", seed " << seed;
    }
}

TEST(PairCalibrationScenario, ARigWithoutRoomForTheCardIsRefusedWithTheReason) {
    SimParameters p;
    p.scenario = "pair-calibration";
    p.projectorFocalPx =
        1100.0;  // a longer throw: the border around the chessboard gets narrower than the card
    try {
        Simulator simulator(p, test::randomPattern(p.projectorSize, 3));
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("the card does not fit"), std::string::npos) << error.what();
    }
}

TEST(PairCalibrationScenario, HoldsSevenStillScenesAndMovesBetweenThem) {
    SimParameters p;
    p.scenario = "pair-calibration";
    Simulator simulator(p, test::randomPattern(p.projectorSize, 3));
    simulator.projectImage(cv::Mat(p.projectorSize, CV_8UC1, cv::Scalar(255)));  // the session begins
    const auto& scenario = dynamic_cast<const PairCalibrationScenario&>(simulator.scenario());
    // Runs of frames showing the same props, at the rig's frame rate, over one cycle and a second beyond.
    const auto frames = static_cast<std::uint64_t>((scenario.cycleSeconds() + 1.0) * p.frameRate);
    std::vector<double> stillSeconds;
    std::vector<bool> withBoard;
    Props previous = scenario.at(0.0).props;
    std::uint64_t runStart = 0;
    for (std::uint64_t k = 1; k <= frames; ++k) {
        const Props props = k < frames ? scenario.at(simulator.frameSeconds(k)).props : Props{};
        if (props == previous && k < frames)
            continue;
        if (k - runStart > 1) {
            stillSeconds.push_back((k - runStart) / p.frameRate);
            withBoard.push_back(previous.board.has_value());
        }
        previous = props;
        runStart = k;
    }
    // The table, five tilts of the board, and the table again once the board is taken away.
    ASSERT_EQ(stillSeconds.size(), 7u);
    EXPECT_FALSE(withBoard.front());
    EXPECT_FALSE(withBoard.back());
    for (size_t k = 0; k + 1 < stillSeconds.size(); ++k) {
        EXPECT_GE(stillSeconds[k], PairCalibrationScenario::kHoldSeconds - 0.02) << "pose " << k;
        if (k > 0) {
            EXPECT_TRUE(withBoard[k]);
        }
    }
    EXPECT_TRUE(scenario.at(scenario.tableAgainAt()).props == (Props{scenario.poses().front().card, {}}));

    // In the middle of every move, frames a tenth of a second apart differ well beyond the noise (the
    // dialogue compares each frame with the first of a still spell of half a second); frames in a hold do
    // not. Pixels that changed by more than 25 DN (the noise of a texture is about 2 DN).
    const auto changed = [](const cv::Mat& x, const cv::Mat& y) {
        cv::Mat difference, gray;
        cv::absdiff(x, y, difference);
        cv::cvtColor(difference, gray, cv::COLOR_BGR2GRAY);
        return cv::countNonZero(gray > 25) / static_cast<double>(gray.total());
    };
    const auto pairAt = [&](double seconds) {
        return renderPair(simulator, static_cast<std::uint64_t>(seconds * p.frameRate) & ~1ull);
    };
    const int last = static_cast<int>(scenario.poses().size()) - 1;
    double leastInMove = 1.0;
    for (int k = 1; k <= last + 1; ++k) {
        const double middle = scenario.holdEnd(k - 1) + PairCalibrationScenario::kMoveSeconds / 2;
        const double inMove = changed(pairAt(middle).texture, pairAt(middle + 0.1).texture);
        RecordProperty("moving_changed_fraction_" + std::to_string(k), std::to_string(inMove));
        leastInMove = std::min(leastInMove, inMove);
    }
    const double still = scenario.holdStart(3) + 0.5;
    const double inHold = changed(pairAt(still).texture, pairAt(still + 0.1).texture);
    EXPECT_GT(leastInMove, 0.002);  // the edges of board, card, stripe and shadow on white content
    EXPECT_LT(inHold, 1e-4);
}

TEST(PairCalibrationScenario, TheUserBeginsWhenTheProjectorFirstShowsTheChessboard) {
    SimParameters p;
    p.scenario = "pair-calibration";
    Simulator simulator(p, test::randomPattern(p.projectorSize, 3));
    const auto& scenario = dynamic_cast<const PairCalibrationScenario&>(simulator.scenario());
    const auto at = [&](double seconds) { return static_cast<std::uint64_t>(seconds * p.frameRate) & ~1ull; };
    // Before the dialogue shows anything the card lies on the table, however long that takes.
    const std::uint64_t waiting = at(scenario.holdStart(2) + 0.5);
    FramePair pair = renderPair(simulator, waiting);
    EXPECT_TRUE(pair.truth.props == (Props{scenario.poses().front().card, {}}));
    // The session begins with the frame after the last one rendered.
    simulator.projectImage(chessboardImage(p.projectorSize));
    const std::uint64_t begun = waiting + 2;
    pair = renderPair(simulator, begun + at(scenario.holdStart(1) + 0.5));
    ASSERT_TRUE(pair.truth.props.board);
    EXPECT_TRUE(pair.truth.props == (Props{scenario.poses()[1].card, scenario.poses()[1].board}));
    pair = renderPair(simulator, begun + at(scenario.tableAgainAt() + 1.0));
    EXPECT_TRUE(pair.truth.props == (Props{scenario.poses().front().card, {}}));
}

TEST(PairCalibrationScenario, ChessboardAndStripeOnEveryBoardPoseAgreeWithTheGeometry) {
    SimParameters p;
    p.scenario = "pair-calibration";
    Simulator simulator(p, test::randomPattern(p.projectorSize, 3));
    const core::Calibration& calibration = simulator.calibration();
    const auto& scenario = dynamic_cast<const PairCalibrationScenario&>(simulator.scenario());
    simulator.projectImage(chessboardImage(p.projectorSize));
    const Eigen::Isometry3d projectorToTable = calibration.tableToProjector.inverse();
    for (int k = 0; k < static_cast<int>(scenario.poses().size()); ++k) {
        const auto index = static_cast<std::uint64_t>((scenario.holdStart(k) + 0.5) * p.frameRate) & ~1ull;
        const FramePair pair = renderPair(simulator, index);
        ASSERT_TRUE(pair.truth.props.card);
        ASSERT_EQ(pair.truth.props.board.has_value(), k > 0);

        const core::Result<core::ChessboardDetection> chessboard =
            core::detectProjectedChessboard(pair.texture, calibrationChessboard(), p.projectorSize);
        ASSERT_TRUE(chessboard.ok()) << "pose " << k << ": " << chessboard.failure().message;
        // Each corner: the projector's ray through it meets the surface, and the camera sees that point.
        const Eigen::Isometry3d surface =
            k > 0 ? pair.truth.props.board->faceToTable : Eigen::Isometry3d::Identity();
        const Eigen::Vector3d normal = surface.linear().col(2), origin = surface.translation();
        double sum2 = 0.0, worst = 0.0;
        for (size_t i = 0; i < chessboard->projectorCorners.size(); ++i) {
            const Eigen::Vector3d direction =
                projectorToTable.linear() *
                (calibration.projectorMatrix.inverse() * chessboard->projectorCorners[i].homogeneous());
            const Eigen::Vector3d centre = projectorToTable.translation();
            const Eigen::Vector3d point =
                centre + direction * (normal.dot(origin - centre) / normal.dot(direction));
            const double error = (project(calibration, point) - chessboard->cameraCorners[i]).norm();
            sum2 += error * error;
            worst = std::max(worst, error);
        }
        const double rms = std::sqrt(sum2 / chessboard->cameraCorners.size());
        RecordProperty("chessboard_rms_px_pose" + std::to_string(k), std::to_string(rms));
        EXPECT_LT(rms, 0.15) << "pose " << k;
        EXPECT_LT(worst, 0.4) << "pose " << k;

        const core::Result<core::TableRectangleDetection> stripe = core::findTableRectangle(pair.texture, {});
        ASSERT_TRUE(stripe.ok()) << "pose " << k << ": " << stripe.failure().message;
        const double error =
            worstCornerError(stripe->corners, stripeInCamera(calibration, *pair.truth.props.card));
        RecordProperty("stripe_corner_error_px_pose" + std::to_string(k), std::to_string(error));
        EXPECT_LT(error, 0.3) << "pose " << k;
    }
}

TEST(Props, AHandOverTheBoardIsSeenAboveItAndShadowsIt) {
    SimParameters p;
    const core::Calibration calibration = rigCalibration(p);
    Renderer renderer(p, calibration, test::randomPattern(p.projectorSize, 3));
    renderer.setContent(renderContent(ContentKind::White, calibration.displaySize, 1, 0));
    const PairCalibrationScenario scenario({calibration, 1, 1.0});
    const PairCalibrationScenario::Pose& pose = scenario.poses()[1];
    renderer.setProps({pose.card, pose.board});

    // An index finger pointing 30 mm above the middle of the board's lit part.
    const Eigen::Isometry3d& face = pose.board->faceToTable;
    Eigen::Vector3d lit = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& corner :
         CalibrationStage(calibration, calibrationChessboard()).chessboardOn(face))
        lit += corner / 4.0;
    const Eigen::Isometry3d board = Eigen::Translation3d(lit - face.translation()) * face;
    HandPose hand;
    for (int f = 0; f < kFingerCount; ++f)
        hand.fingers[f] = pointingJoints(static_cast<Finger>(f));
    hand.place({0, 0, 0}, -90.0, 30.0);
    movePadTo(hand, Finger::Index, board * Eigen::Vector3d(0, 0, 30.0));
    const double exposure = renderer.meterExposureMs(p.ambientLux);
    cv::Mat with, without;
    FrameTruth truth, bare;
    renderer.render({{hand}}, core::Polarity::Positive, p.ambientLux, exposure, 5, with, truth);
    renderer.render({{}}, core::Polarity::Positive, p.ambientLux, exposure, 5, without, bare);
    EXPECT_EQ(truth.props, bare.props);
    ASSERT_GT(cv::countNonZero(truth.handMask), 1000);

    // The board's visible heights in the truth; the hand above it.
    const Eigen::Vector2d middle = project(calibration, board.translation());
    EXPECT_NEAR(bare.visibleHeightMm.at<float>(static_cast<int>(middle.y()), static_cast<int>(middle.x())),
                board.translation().z(), 1.0);
    const FingertipTruth& index = truth.fingertips[static_cast<int>(Finger::Index)];
    EXPECT_NEAR(index.pad.z(), (board * Eigen::Vector3d(0, 0, 30.0)).z(), 1e-6);

    // Its shadow: board pixels outside the hand that lost most of the projector's light.
    cv::Mat withGray, withoutGray;
    cv::cvtColor(with, withGray, cv::COLOR_BGR2GRAY);
    cv::cvtColor(without, withoutGray, cv::COLOR_BGR2GRAY);
    cv::Mat darker = (withoutGray - withGray) > 40;
    darker.setTo(0, truth.handMask);
    darker.setTo(0, bare.visibleHeightMm < 1.0f);  // the table
    EXPECT_GT(cv::countNonZero(darker), 200);
}

}  // namespace
}  // namespace everytouch::sim
