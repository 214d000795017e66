#include "core/registration_check.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "core/camera_model.h"
#include "core/geometry.h"
#include "core/table_code.h"

namespace everytouch::core {

namespace {

// The local means taken out of S and of the prediction, as for the code's blur: the content's brightness and
// the table's albedo hardly change across it, and it holds many code bits.
constexpr int kLocalMeanPx = 9;
// A tile counts when this share of it lies where the code can be read.
constexpr double kMinUsableShare = 0.95;
// Hands and forearms cover less than this share of the table.
constexpr double kMostHandShare = 0.5;
// The whole reach is searched on every third pixel of the tile each way: a ninth of the work, samples
// nearly independent through a blur of about a pixel, the true peak still far above chance (256 samples of
// a 48-pixel tile), and the candidate refined on every pixel.
constexpr int kSparseStep = 3;

// Normalised correlation of two equally sized CV_32FC1 images, the second's sum of squares given; 0 when
// either is flat.
double normalisedCorrelation(const cv::Mat& a, const cv::Mat& b, double bSquares) {
    const double squares = a.dot(a) * bSquares;
    return squares > 0.0 ? a.dot(b) / std::sqrt(squares) : 0.0;
}

// The offset of a parabola's vertex through three samples one apart, from the middle one.
double vertexOffset(double left, double centre, double right) {
    const double curvature = left - 2.0 * centre + right;
    return curvature < 0.0 ? std::clamp(0.5 * (left - right) / curvature, -0.5, 0.5) : 0.0;
}

}  // namespace

std::optional<std::string> RegistrationOptions::validate() const {
    if (tilePx < 16 || tilePx > 256)
        return "tilePx: must be 16 to 256 pixels";
    if (!(searchMm > 0.0) || !std::isfinite(searchMm))
        return "searchMm: must be positive";
    if (trackPx < 1)
        return "trackPx: must be at least 1 pixel";
    if (tilesPerPair < 1 || triesPerPair < tilesPerPair)
        return "tilesPerPair: must be at least 1, and triesPerPair at least as many";
    if (!(significance > 0.0) || !std::isfinite(significance))
        return "significance: must be positive";
    if (tilesPerEstimate < 1)
        return "tilesPerEstimate: must be at least 1";
    return std::nullopt;
}

RegistrationCheck::RegistrationCheck(const RegistrationOptions& options) : options_(options) {
    if (auto problem = options.validate())
        throw std::invalid_argument("registration options: " + *problem);
    latest_.reserve(static_cast<std::size_t>(options.tilesPerEstimate));
    lengths_.reserve(static_cast<std::size_t>(options.tilesPerEstimate));
}

void RegistrationCheck::setRig(const Calibration& calibration, const cv::Mat& pattern, const cv::Mat& region,
                               double cameraBlurPx) {
    CV_Assert(region.type() == CV_8UC1 && region.size() == calibration.cameraSize);
    tiles_.clear();
    latest_.clear();
    measured_ = 0;
    next_ = 0;

    // The search's reach in camera pixels, from the table's scale at the display's centre.
    const Eigen::Matrix3d tableToCamera = calibration.tableToCameraHomography();
    const Eigen::Vector2d centreMm = calibration.displayCentreOnTable();
    const double pixelsPerMm = (applyHomography(tableToCamera, centreMm + Eigen::Vector2d(1.0, 0.0)) -
                                applyHomography(tableToCamera, centreMm))
                                   .norm();
    searchPx_ = std::clamp(static_cast<int>(std::ceil(options_.searchMm * pixelsPerMm)), options_.trackPx + 1,
                           options_.tilePx);

    const TableCode code = predictTableCode(calibration, pattern, cameraBlurPx);
    cv::Mat localMean;
    cv::boxFilter(code.predicted, localMean, CV_32F, {kLocalMeanPx, kLocalMeanPx});
    prediction_ = code.predicted - localMean;
    cv::Mat usable = (code.predicted >= 0.0f) & region;
    // Pixels near the edge of the light carry the dark beyond it in their local mean.
    cv::erode(usable, usable, cv::getStructuringElement(cv::MORPH_RECT, {kLocalMeanPx, kLocalMeanPx}));
    regionPixels_ = cv::countNonZero(region);

    const CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    const Eigen::Matrix3d toProjector = calibration.cameraToProjectorHomography();
    const auto onPanel = [&](const Eigen::Vector2d& pixel) {
        return applyHomography(toProjector, camera.undistortPixel(pixel));
    };
    const cv::Rect image({0, 0}, calibration.cameraSize);
    const int tile = options_.tilePx;
    for (int y = searchPx_; y + tile + searchPx_ <= image.height; y += tile)
        for (int x = searchPx_; x + tile + searchPx_ <= image.width; x += tile) {
            const cv::Rect box(x, y, tile, tile);
            if (cv::countNonZero(usable(box)) < kMinUsableShare * box.area())
                continue;
            Tile& added = tiles_.emplace_back();
            added.box = box;
            added.centre = {x + tile / 2.0, y + tile / 2.0};
            const Eigen::Vector2d here = onPanel(added.centre);
            added.cameraToProjector.col(0) = onPanel(added.centre + Eigen::Vector2d(1.0, 0.0)) - here;
            added.cameraToProjector.col(1) = onPanel(added.centre + Eigen::Vector2d(0.0, 1.0)) - here;
        }
    // Consecutive tiles a golden section of the round apart: every few pairs look at all of the table.
    const std::size_t count = tiles_.size();
    stride_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(0.618 * count)));
    while (count > 1 && std::gcd(stride_, count) != 1)
        ++stride_;
    // Neighbouring pixels share light through the blur: about two pixels per independent sample.
    chance_ = std::sqrt(2.0 / (tile * tile));
    const int window = tile + 2 * searchPx_;
    window_.create(window, window, CV_32FC1);
    rowSums_.create(window, window, CV_32FC1);
    columnSums_.resize(static_cast<std::size_t>(window));
    const int sparseWindow = (window + kSparseStep - 1) / kSparseStep;
    sparseWindows_.resize(kSparseStep * kSparseStep);
    for (cv::Mat& phase : sparseWindows_)
        phase.create(sparseWindow, sparseWindow, CV_32FC1);
    const int sparseTile = (tile + kSparseStep - 1) / kSparseStep;
    sparseTile_.create(sparseTile, sparseTile, CV_32FC1);
    correlation_.create(2 * options_.trackPx + 1, 2 * options_.trackPx + 1, CV_64FC1);
}

void RegistrationCheck::prepareWindow(const Tile& tile, const cv::Mat& subtraction) {
    const cv::Rect reach(tile.box.x - searchPx_, tile.box.y - searchPx_, window_.cols, window_.rows);
    subtraction(reach).convertTo(window_, CV_32F);
    // The local mean over the box, cut at the window's edge; as a running sum, first along the rows into
    // rowSums_, then down the columns.
    constexpr int half = kLocalMeanPx / 2;
    const int rows = window_.rows, cols = window_.cols;
    for (int y = 0; y < rows; ++y) {
        const float* in = window_.ptr<float>(y);
        float* out = rowSums_.ptr<float>(y);
        float sum = 0.0f;
        for (int x = 0; x < std::min(half, cols); ++x)
            sum += in[x];
        for (int x = 0; x < cols; ++x) {
            if (x + half < cols)
                sum += in[x + half];
            if (x - half - 1 >= 0)
                sum -= in[x - half - 1];
            out[x] = sum;
        }
    }
    for (int x = 0; x < cols; ++x) {
        float sum = 0.0f;
        for (int y = 0; y < std::min(half, rows); ++y)
            sum += rowSums_.at<float>(y, x);
        for (int y = 0; y < rows; ++y) {
            if (y + half < rows)
                sum += rowSums_.at<float>(y + half, x);
            if (y - half - 1 >= 0)
                sum -= rowSums_.at<float>(y - half - 1, x);
            columnSums_[static_cast<std::size_t>(y)] = sum;
        }
        const int across = std::min(x + half, cols - 1) - std::max(x - half, 0) + 1;
        for (int y = 0; y < rows; ++y) {
            const int down = std::min(y + half, rows - 1) - std::max(y - half, 0) + 1;
            window_.at<float>(y, x) -=
                columnSums_[static_cast<std::size_t>(y)] / static_cast<float>(across * down);
        }
    }
}

cv::Point RegistrationCheck::coarsePeak(const Tile& tile) {
    // The window split into its kSparseStep^2 phases: a shift's samples are then one block of one phase.
    for (int y = 0; y < window_.rows; ++y) {
        const float* row = window_.ptr<float>(y);
        for (int x = 0; x < window_.cols; ++x)
            sparseWindows_[(y % kSparseStep) * kSparseStep + x % kSparseStep].at<float>(
                y / kSparseStep, x / kSparseStep) = row[x];
    }
    for (int y = 0; y < sparseTile_.rows; ++y)
        for (int x = 0; x < sparseTile_.cols; ++x)
            sparseTile_.at<float>(y, x) =
                prediction_.at<float>(tile.box.y + kSparseStep * y, tile.box.x + kSparseStep * x);
    const double tileSquares = sparseTile_.dot(sparseTile_);
    double best = -1.0;
    cv::Point bestShift{0, 0};
    for (int dy = -searchPx_; dy <= searchPx_; ++dy)
        for (int dx = -searchPx_; dx <= searchPx_; ++dx) {
            const int ox = dx + searchPx_, oy = dy + searchPx_;
            const cv::Mat& phase = sparseWindows_[(oy % kSparseStep) * kSparseStep + ox % kSparseStep];
            const cv::Rect block(ox / kSparseStep, oy / kSparseStep, sparseTile_.cols, sparseTile_.rows);
            if (block.br().x > phase.cols || block.br().y > phase.rows)
                continue;
            if (const double value = normalisedCorrelation(phase(block), sparseTile_, tileSquares);
                value > best) {
                best = value;
                bestShift = {dx, dy};
            }
        }
    return bestShift;
}

std::optional<TileShift> RegistrationCheck::refine(const Tile& tile, cv::Point around, int radius) {
    const cv::Mat predicted = prediction_(tile.box);
    const double predictedSquares = predicted.dot(predicted);
    double peak = -1.0;
    cv::Point at;
    for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx) {
            const cv::Rect shifted(searchPx_ + around.x + dx, searchPx_ + around.y + dy, tile.box.width,
                                   tile.box.height);
            const double value = normalisedCorrelation(window_(shifted), predicted, predictedSquares);
            correlation_.at<double>(dy + radius, dx + radius) = value;
            if (value > peak) {
                peak = value;
                at = {dx + radius, dy + radius};
            }
        }
    // A peak on the search's edge may lie beyond it.
    const int last = 2 * radius;
    if (!(peak >= options_.significance * chance_) || at.x == 0 || at.y == 0 || at.x == last || at.y == last)
        return std::nullopt;
    const auto sample = [&](int x, int y) { return correlation_.at<double>(y, x); };
    TileShift shift;
    shift.cameraPx = {
        around.x + at.x - radius + vertexOffset(sample(at.x - 1, at.y), peak, sample(at.x + 1, at.y)),
        around.y + at.y - radius + vertexOffset(sample(at.x, at.y - 1), peak, sample(at.x, at.y + 1))};
    shift.projectorPx = tile.cameraToProjector * shift.cameraPx;
    shift.centre = tile.centre;
    shift.correlation = peak;
    return shift;
}

void RegistrationCheck::update(const cv::Mat& subtraction, const cv::Mat& handMask,
                               std::int64_t timestampUs) {
    CV_Assert(subtraction.type() == CV_16SC1 && handMask.type() == CV_8UC1 &&
              handMask.size() == subtraction.size());
    if (tiles_.empty() || subtraction.size() != prediction_.size())
        return;
    // A mask over most of the table is no hand: it is what the segmentation makes of a table whose code is
    // not where the calibration predicts it, which is what this check is there to see. Every tile is then
    // read, and the median stands against the tiles a hand does cover.
    const bool maskIsAHand = cv::countNonZero(handMask) < kMostHandShare * regionPixels_;
    int measuredNow = 0;
    for (int tried = 0; tried < options_.triesPerPair && measuredNow < options_.tilesPerPair; ++tried) {
        Tile& tile = tiles_[next_];
        next_ = (next_ + stride_) % tiles_.size();
        const cv::Rect window(tile.box.x - searchPx_, tile.box.y - searchPx_, tile.box.width + 2 * searchPx_,
                              tile.box.height + 2 * searchPx_);
        if (maskIsAHand && cv::countNonZero(handMask(window)) > 0)
            continue;
        ++measuredNow;
        prepareWindow(tile, subtraction);
        const auto within = [&](cv::Point shift) {
            return std::max(std::abs(shift.x), std::abs(shift.y)) + options_.trackPx <= searchPx_;
        };
        std::optional<TileShift> shift;
        if (within(tile.expected))
            shift = refine(tile, tile.expected, options_.trackPx);
        if (!shift) {
            const cv::Point candidate = coarsePeak(tile);
            if (within(candidate))
                shift = refine(tile, candidate, options_.trackPx);
        }
        if (!shift)
            continue;
        tile.expected = {static_cast<int>(std::lround(shift->cameraPx.x())),
                         static_cast<int>(std::lround(shift->cameraPx.y()))};
        shift->timestampUs = timestampUs;
        if (latest_.size() == static_cast<std::size_t>(options_.tilesPerEstimate))
            latest_.erase(latest_.begin());
        latest_.push_back(*shift);
        ++measured_;
    }
}

std::optional<double> RegistrationCheck::errorPx() const {
    if (latest_.size() < static_cast<std::size_t>(options_.tilesPerEstimate))
        return std::nullopt;
    lengths_.clear();
    for (const TileShift& shift : latest_)
        lengths_.push_back(shift.projectorPx.norm());
    const auto middle = lengths_.begin() + static_cast<std::ptrdiff_t>(lengths_.size() / 2);
    std::nth_element(lengths_.begin(), middle, lengths_.end());
    return *middle;
}

}  // namespace everytouch::core
