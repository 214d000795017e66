#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/calibration.h"
#include "core/camera_model.h"
#include "core/registration_check.h"

namespace everytouch::core {

struct CorrectionOptions {
    // A move is corrected when it explains a misregistration (RMS over the tiles, projector pixels) of at
    // least this many times the tiles' own noise, the scatter the move leaves unexplained: a move of noise
    // alone explains about 0.6 times the noise over 16 tiles (6 parameters of 32 coordinates).
    double noiseMultiple = 3.0;
    // ... and of at least this much, projector pixels: on the default rig 1 mm of height moves the code by
    // 0.19 projector pixels, and a fingertip's height already scatters by about a millimetre from tap to tap,
    // so a smaller misregistration changes no touch, and correcting it would only chase the calibration's own
    // small errors.
    double leastErrorPx = 0.2;

    std::optional<std::string> validate() const;
};

// A calibration corrected from the code on the table.
struct CalibrationCorrection {
    Calibration calibration;  // the corrected one
    double beforePx = 0.0;    // the misregistration over the tiles it rests on, RMS, projector pixels
    double afterPx = 0.0;     // what the corrected calibration leaves of it, RMS, projector pixels
    std::string what;         // what moved: "camera", "table" (its plane under the rig), or "projector"
                              // (its image crept on its panel)
    int tiles = 0;
};

// Keeps the calibration true when the camera is knocked or its mount sags, the table tilts under the rig, or
// the projector's image creeps as a warm projector's does. After every round of tiles the registration check
// measures (core/registration_check.h), it fits three explanations to their shifts by least squares (in
// projector pixels, the scale the code is read in): a small move of the camera against the table (the shifts
// each of the camera pose's six parameters would cause), a move of the table's plane under both devices
// (turns about its two level axes through the display's centre and a lift: three parameters), and a shift of
// the projector's image on its panel (its principal point: the same shift of every projector pixel, two
// parameters). The image's shift is taken whenever what it leaves would count as the calibration holding
// (below), else the table's plane when what it leaves would, else the camera's move: a small move of the
// camera also shifts the code nearly evenly, but a creep corrected as many such moves adds up to a pose that
// no longer fits (the whole table 0.2-0.3 px off after 9 px of creep), while a knocked camera leaves far more
// after any shift of the image. What the chosen explanation leaves is the tiles' noise. When it explains a
// misregistration that is large against that noise and against leastErrorPx, the calibration is corrected
// (the camera's pose estimated anew from the tiles, core/camera_relocation.h; the table's plane moved by
// the fitted move, refined over the tiles; or the projector's principal point moved by the fitted shift) and
// the correction kept when it leaves less than leastErrorPx or no more than noiseMultiple times the noise
// seen while the calibration held (or, before any such round, the noise of this one). The calibration holds
// while the misregistration stays below leastErrorPx and below noiseMultiple times that noise. A
// misregistration that none explains, leaving leastErrorPx or more (a warped table), is not corrected;
// problem() says why once two rounds running found it. One that an explanation accounts for but not yet
// clearly beyond the noise, leaving less than leastErrorPx, is watched without a problem. Tiles far off the
// move that fits the others (a peak of chance, a tile read while the camera moved) are set aside first. Pure;
// a round that finds nothing allocates nothing.
class CalibrationCorrector {
public:
    // Throws std::invalid_argument when options.validate() fails.
    explicit CalibrationCorrector(const CorrectionOptions& options = {});

    // The calibration the tiles are measured against; tilesPerRound: how many new tiles make a round (the
    // check's tilesPerEstimate). Forgets the noise seen so far.
    void setRig(const Calibration& calibration, int tilesPerRound);

    // `measured`: how many tiles the check has measured since its rig was set; `latest`: its latest tiles.
    // Once a round of new tiles is in, judges them: a correction when one is warranted and confident.
    std::optional<CalibrationCorrection> update(std::uint64_t measured, const std::vector<TileShift>& latest);

    // Why the last round's misregistration, although large, was not corrected; empty when it was or when
    // there was nothing to correct.
    const std::string& problem() const { return problem_; }

private:
    struct Fit {
        double beforePx = 0.0;     // RMS shift over the tiles, projector pixels
        double explainedPx = 0.0;  // RMS of the part the explanation accounts for
        double leftPx = 0.0;       // RMS per tile of the rest: what the explanation leaves
        double noisePx = 0.0;      // the same, corrected for the parameters fitted
    };
    // What the check measured at one tile, in the terms of a camera pose: the table point the projector
    // lights through the code predicted at the tile's centre, where the camera now sees it, and how camera
    // pixels there map to projector pixels.
    struct TileGeometry {
        Eigen::Vector2d panelPixel;  // the projector pixel whose code the calibration predicts at the centre
        Eigen::Vector3d tablePoint;
        Eigen::Vector2d observed;
        Eigen::Matrix2d toProjector;
    };
    static TileGeometry tileGeometry(const CameraModel& camera, const Eigen::Matrix3d& cameraToProjector,
                                     const Eigen::Matrix3d& projectorToTable, const TileShift& tile);
    // One tile's equations in projector pixels: the shift each parameter of the camera's pose would cause,
    // the shift each pixel of the projector image's own shift would cause, and the shift measured.
    struct TileTerm {
        TileGeometry geometry;
        Eigen::Matrix<double, 2, 6> onPanel;
        Eigen::Matrix2d imageOnPanel;
        Eigen::Matrix<double, 2, 3> tableOnPanel;
        Eigen::Vector2d shift;
        bool inlier = true;
        double residualPx = 0.0;  // what the last fit left of the shift
    };
    void prepareTerms(const std::vector<TileShift>& tiles);
    // A fit over `tiles` tiles whose shifts' squares sum to `squares` before and `left` after fitting
    // `parameters` parameters.
    static Fit summarise(double squares, double left, int tiles, int parameters);
    Fit fitMove();  // over the inlier terms
    Fit fitMoveRobustly(const std::vector<TileShift>& tiles);
    // The parameters of a linear explanation that fit the inlier terms best, each term's shifts per parameter
    // in `onPanel`: the projector image's shift (imageOnPanel, projector pixels) or the table's plane's move
    // (tableOnPanel: turns about its level axes through the display's centre, radians, and a lift, mm).
    template <int N>
    Fit fitLinear(Eigen::Matrix<double, 2, N> TileTerm::*onPanel,
                  Eigen::Matrix<double, N, 1>& parameters) const;
    // The calibration with the table's plane moved, refined from the linear fit `move` over the inlier terms.
    Calibration refinedTable(Eigen::Vector3d move) const;
    // Where the camera of `calibration` sees the light of projector pixel `panelPixel` on its table.
    static Eigen::Vector2d seenThrough(const Calibration& calibration, const CameraModel& camera,
                                       const Eigen::Vector2d& panelPixel);
    // RMS distance, projector pixels, between each inlier tile's observed place and where `corrected` puts
    // the table point its panel pixel lights.
    double inlierMisregistrationPx(const Calibration& corrected) const;

    CorrectionOptions options_;
    std::optional<Calibration> calibration_;
    Eigen::Vector3d tableCentre_ = Eigen::Vector3d::Zero();  // the display's centre on the table, mm
    int tilesPerRound_ = 16;
    std::uint64_t judged_ = 0;           // the check's tile count at the last round
    std::optional<double> heldNoisePx_;  // the tiles' noise in the last round that found nothing to correct
    int roundsOff_ = 0;                  // rounds running that found a misregistration and did not correct it
    std::string problem_;
    // Scratch, reserved for a round by setRig.
    std::vector<TileTerm> terms_;
    std::vector<double> residuals_;
    std::vector<TileShift> inliers_;
};

}  // namespace everytouch::core
