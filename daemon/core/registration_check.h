#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "core/calibration.h"

namespace everytouch::core {

struct RegistrationOptions {
    // Side of a tile, camera pixels: enough code bits that its correlation with the prediction has one sharp
    // peak (48 x 48 pixels hold some 2 300 samples, chance correlations of 0.03), small enough that a
    // misregistration is one shift across it.
    int tilePx = 48;
    // How far the code may have moved on the table and still be found, mm: a camera turned by 0.5 degrees
    // a metre above the table moves it 9 mm, and a knock that moves it further is found as far as this.
    double searchMm = 12.0;
    // Each tile is first sought within this many camera pixels of its last shift, which holds while nothing
    // moves; only when the code is not found there is the whole reach searched.
    int trackPx = 2;
    // Tiles measured per pair at most, and tiles tried per pair (a tile the hand covers is passed over):
    // bounds the cost per pair.
    int tilesPerPair = 1;
    int triesPerPair = 3;
    // A tile's correlation peak must exceed this many standard deviations of chance to count: over print or
    // shadow the code is too faint for a place.
    double significance = 6.0;
    // The error is the median over this many of the latest tiles measured (spread over the table by the
    // order they are visited in): at 120 pairs/s, 0.13 s of tiles.
    int tilesPerEstimate = 16;

    std::optional<std::string> validate() const;
};

// One tile's measurement: where the code on the table lies against where the calibration predicts it.
struct TileShift {
    Eigen::Vector2d cameraPx = Eigen::Vector2d::Zero();     // the code's shift in the image, camera pixels
    Eigen::Vector2d projectorPx = Eigen::Vector2d::Zero();  // the same on the panel, projector pixels
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();       // the tile's centre, camera pixels
    double correlation = 0.0;                               // the peak's normalised correlation
    std::int64_t timestampUs = 0;
};

// Checks the calibration against the code the table shows in every pair, a few tiles at a time: each tile of
// S (its local mean taken out) is correlated with the code the calibration predicts there, blurred as the
// rig blurs it, over every shift within searchMm; the peak, refined to a fraction of a pixel, is how far the
// code lies from where the calibration puts it, carried onto the panel through the table's homography. A
// calibration that holds shows shifts of a few hundredths of a pixel (the noise of the peak); a camera that
// was knocked, a table that tilted or a projector whose image crept show the same shift in tile after tile.
// Tiles the hand or its margin covers are passed over, unless the mask covers most of the table; the tiles
// are visited in an order that spreads consecutive ones over the table. Pure; allocates nothing per pair once
// the rig is set.
class RegistrationCheck {
public:
    // Throws std::invalid_argument when options.validate() fails.
    explicit RegistrationCheck(const RegistrationOptions& options = {});

    // region: CV_8UC1, camera size, nonzero where the table's code is to be read. cameraBlurPx: the code's
    // blur on this rig (core/code_blur.h). Forgets every measurement.
    void setRig(const Calibration& calibration, const cv::Mat& pattern, const cv::Mat& region,
                double cameraBlurPx);
    bool hasRig() const { return !tiles_.empty(); }
    int tileCount() const { return static_cast<int>(tiles_.size()); }

    // Measures the next tiles of the round in S (CV_16SC1, camera size, in O+P minus O-P order) that the hand
    // mask (CV_8UC1, nonzero on the hand) leaves free.
    void update(const cv::Mat& subtraction, const cv::Mat& handMask, std::int64_t timestampUs);

    // The misregistration, projector pixels: the median of the shifts' lengths over the latest
    // tilesPerEstimate tiles; nothing before that many were measured since the rig was set.
    std::optional<double> errorPx() const;
    // The latest tiles measured, oldest first, at most tilesPerEstimate.
    const std::vector<TileShift>& latest() const { return latest_; }
    // Tiles measured since the rig was set.
    std::uint64_t measured() const { return measured_; }

private:
    struct Tile {
        cv::Rect box;                       // the tile, camera pixels
        Eigen::Matrix2d cameraToProjector;  // the homography's derivative at its centre
        Eigen::Vector2d centre;
        cv::Point expected{0, 0};  // its last shift, whole camera pixels: where the search begins
    };
    // S over the tile's whole reach, its local mean taken out, into window_.
    void prepareWindow(const Tile& tile, const cv::Mat& subtraction);
    // The shift within `radius` of `around` (whole pixels, within the reach), when the peak is significant
    // and inside that radius.
    std::optional<TileShift> refine(const Tile& tile, cv::Point around, int radius);
    // The whole reach, on every kSparseStep-th pixel of the tile in each direction: the candidate to refine.
    cv::Point coarsePeak(const Tile& tile);

    RegistrationOptions options_;
    int searchPx_ = 0;
    int regionPixels_ = 0;  // the table's region's
    double chance_ = 1.0;
    cv::Mat prediction_;  // CV_32FC1, camera size: the predicted code less its local mean
    std::vector<Tile> tiles_;
    std::size_t next_ = 0;  // the tile the round goes on with
    std::size_t stride_ = 1;
    std::vector<TileShift> latest_;
    std::uint64_t measured_ = 0;
    // Scratch, sized by setRig: the reach's window of S and its local mean, its sparse phases, the
    // sparse tile and the correlations of a refinement.
    cv::Mat window_, rowSums_;  // S over the reach; the local mean's sums along its rows
    std::vector<float> columnSums_;
    std::vector<cv::Mat> sparseWindows_;
    cv::Mat sparseTile_;
    cv::Mat correlation_;
    mutable std::vector<double> lengths_;
};

}  // namespace everytouch::core
