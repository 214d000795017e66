#include "core/surface_height.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include "core/camera_model.h"
#include "core/finger_section.h"
#include "core/geometry.h"

namespace everytouch::core {

// Bilinear sampling of a CV_32FC1 image; -1 outside.
class BilinearSampler {
public:
    explicit BilinearSampler(const cv::Mat& image)
        : data_(image.ptr<float>()),
          step_(static_cast<std::ptrdiff_t>(image.step1())),
          lastX_(image.cols - 1),
          lastY_(image.rows - 1) {}

    const float* data() const { return data_; }
    std::ptrdiff_t step() const { return step_; }
    int lastX() const { return lastX_; }
    int lastY() const { return lastY_; }

    float operator()(float x, float y) const {
        if (!(x >= 0.0f && y >= 0.0f))
            return -1.0f;
        const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);  // truncation is the floor here
        if (x0 >= lastX_ || y0 >= lastY_)
            return -1.0f;
        const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
        const float* row0 = data_ + y0 * step_ + x0;
        const float* row1 = row0 + step_;
        const float top = row0[0] + (row0[1] - row0[0]) * fx;
        const float bottom = row1[0] + (row1[1] - row1[0]) * fx;
        return top + (bottom - top) * fy;
    }

private:
    const float* data_;
    std::ptrdiff_t step_;
    int lastX_, lastY_;
};

namespace {

// A pixel of a pair summed over its channels: the frames' difference (Sign -1), which carries the code and
// what a move leaves, or their sum (Sign +1), twice the texture.
template <int Channels, int Sign>
float channelSum(const cv::Mat& plus, const cv::Mat& minus, int x, int y) {
    const uchar* p = plus.ptr<uchar>(y) + Channels * x;
    const uchar* m = minus.ptr<uchar>(y) + Channels * x;
    int sum = 0;
    for (int c = 0; c < Channels; ++c)
        sum += p[c] + Sign * m[c];
    return static_cast<float>(sum);
}

template <int Channels>
cv::Point2f textureGradient(const cv::Mat& plus, const cv::Mat& minus, int x, int y) {
    const auto texture = [&](int tx, int ty) { return channelSum<Channels, 1>(plus, minus, tx, ty); };
    return {0.5f * (texture(x + 1, y) - texture(x - 1, y)), 0.5f * (texture(x, y + 1) - texture(x, y - 1))};
}

}  // namespace

std::optional<std::string> HeightOptions::validate() const {
    if (!(maxHeightMm > 0.0 && maxHeightMm <= 200.0))
        return "maxHeightMm: must be in (0, 200] mm";
    if (!(stepMm > 0.0 && stepMm <= maxHeightMm))
        return "stepMm: must be positive and at most maxHeightMm";
    if (!(skinScatterMm >= 0.0 && skinScatterMm < 10.0))
        return "skinScatterMm: must be in [0, 10) mm";
    if (!(regionWidths > 0.0 && regionWidths <= 3.0))
        return "regionWidths: must be in (0, 3] finger widths";
    if (!(centreBehindWidths >= 0.0 && centreBehindWidths <= 3.0))
        return "centreBehindWidths: must be in [0, 3] finger widths";
    if (!(significance > 0.0) || !std::isfinite(significance))
        return "significance: must be a positive number of standard deviations";
    if (!(distinctness >= 0.0) || !std::isfinite(distinctness))
        return "distinctness: must be a number of standard deviations, not negative";
    if (!(thicknessPerWidth > 0.0 && thicknessPerWidth <= 2.0))
        return "thicknessPerWidth: must be in (0, 2]";
    if (!(maxSlope >= 0.0 && maxSlope <= 5.0))
        return "maxSlope: must be in [0, 5] mm per mm";
    if (!(slopeStep > 0.0 && slopeStep <= 5.0))
        return "slopeStep: must be in (0, 5] mm per mm";
    return std::nullopt;
}

void HeightEvidence::clear(std::size_t heights) {
    covariance.assign(heights, 0.0);
    codeVariance.assign(heights, 0.0);
    subtractionVariance = 0.0;
    pixels = 0.0;
    topAbovePadTimesPixels = 0.0;
}

void HeightEvidence::add(const HeightEvidence& other, double weight) {
    if (covariance.size() != other.covariance.size())
        clear(other.covariance.size());
    for (std::size_t i = 0; i < covariance.size(); ++i) {
        covariance[i] += weight * other.covariance[i];
        codeVariance[i] += weight * other.codeVariance[i];
    }
    subtractionVariance += weight * other.subtractionVariance;
    pixels += weight * other.pixels;
    topAbovePadTimesPixels += weight * other.topAbovePadTimesPixels;
}

void SlopeSupport::clear(std::size_t slopes) {
    logLikelihood.assign(slopes, 0.0);
}

void SlopeSupport::add(const SlopeSupport& other, double weight) {
    if (logLikelihood.size() != other.logLikelihood.size())
        clear(other.logLikelihood.size());
    for (std::size_t i = 0; i < logLikelihood.size(); ++i)
        logLikelihood[i] += weight * other.logLikelihood[i];
}

SurfaceHeight::SurfaceHeight(const HeightOptions& options) : options_(options) {
    if (auto problem = options.validate())
        throw std::invalid_argument("height options: " + *problem);
    heightCount_ = static_cast<std::size_t>(std::floor(options_.maxHeightMm / options_.stepMm + 1e-9)) + 1;
    slopeCount_ = static_cast<std::size_t>(std::floor(options_.maxSlope / options_.slopeStep + 1e-9)) + 1;
}

void SurfaceHeight::setRig(const Calibration& calibration, const cv::Mat& pattern) {
    CV_Assert(pattern.type() == CV_8UC1 && pattern.size() == calibration.projectorSize);
    // The scales at the display's centre: a camera pixel's footprint and a millimetre, in projector pixels.
    const Eigen::Matrix3d tableToProjector = calibration.tableToProjectorHomography(0.0);
    const Eigen::Vector2d centreMm = calibration.displayCentreOnTable();
    const double projectorPixelsPerMm =
        (applyHomography(tableToProjector, centreMm + Eigen::Vector2d(0.5, 0)) -
         applyHomography(tableToProjector, centreMm - Eigen::Vector2d(0.5, 0)))
            .norm();
    const Eigen::Matrix3d cameraToProjector = calibration.cameraToProjectorHomography(0.0);
    const Eigen::Vector2d centrePx = applyHomography(calibration.tableToCameraHomography(0.0), centreMm);
    const double footprint = (applyHomography(cameraToProjector, centrePx + Eigen::Vector2d(1, 0)) -
                              applyHomography(cameraToProjector, centrePx))
                                 .norm();
    const double sigma =
        std::hypot(kBoxSigmaPerWidth * footprint, options_.skinScatterMm * projectorPixelsPerMm);
    pattern.convertTo(panel_, CV_32FC1);
    cv::GaussianBlur(panel_, panel_, cv::Size(), sigma);
    // A ray's profile is sampled this far apart and interpolated in between. A straight line over h across a
    // code blurred by sigma errs by at most h^2/8 times its largest second derivative, 0.24/sigma^2 of the
    // contrast: 3 % at h = sigma, no more than the panel's own bilinear interpolation over its pixel grid.
    profileSpacingPx_ = std::min(sigma, 1.0);

    // The camera's rays in table coordinates and the projector's view of them: a pixel's ray meets the plane
    // at height d in a point the projector sees at a + d b (homogeneous), a and b from the ray alone.
    const Eigen::Matrix3d cameraToTableRotation = calibration.tableToCamera.rotation().transpose();
    rayFromPixel_ = cameraToTableRotation * calibration.cameraMatrix.inverse();
    cameraCentre_ = -(cameraToTableRotation * calibration.tableToCamera.translation());
    projectorRotation_ = calibration.projectorMatrix * calibration.tableToProjector.rotation();
    epipole_ = calibration.projectorMatrix * (calibration.tableToProjector * cameraCentre_);

    // Regions are a fingertip or a sample of a hand: this many pixels at most, in practice.
    constexpr std::size_t kTypicalMostPixels = 8192;
    values_.reserve(kTypicalMostPixels);
    points_.reserve(kTypicalMostPixels);
    gradients_.reserve(kTypicalMostPixels);
    residuals_.reserve(kTypicalMostPixels);
    rays_.reserve(kTypicalMostPixels);
    shape_.reserve(kTypicalMostPixels);
    blendOffsets_.reserve(kTypicalMostPixels);
    blendWeights_.reserve(kTypicalMostPixels);

    const CameraModel camera{calibration.cameraMatrix, calibration.cameraDistortion};
    undistorted_.create(calibration.cameraSize, CV_32FC2);
    for (int y = 0; y < undistorted_.rows; ++y)
        for (int x = 0; x < undistorted_.cols; ++x) {
            const Eigen::Vector2d u = camera.undistortPixel(Eigen::Vector2d(x, y));
            undistorted_.at<cv::Vec2f>(y, x) =
                cv::Vec2f(static_cast<float>(u.x()), static_cast<float>(u.y()));
        }
}

void SurfaceHeight::clearPixels() {
    shape_.clear();
    values_.clear();
    points_.clear();
    gradients_.clear();
}

void SurfaceHeight::addPixel(const cv::Mat& subtraction, int x, int y) {
    addValue(subtraction.at<short>(y, x), x, y);
}

void SurfaceHeight::addValue(float value, int x, int y) {
    values_.push_back(value);
    const cv::Vec2f& u = undistorted_.at<cv::Vec2f>(y, x);
    points_.emplace_back(u[0], u[1]);
}

void SurfaceHeight::measureFingertip(const FramePair& pair, const cv::Mat& handMask,
                                     const Eigen::Vector2d& tip, const Eigen::Vector2d& direction,
                                     double widthPx, HeightEvidence& evidence) {
    const cv::Mat& plus = pair.positive.image;
    const cv::Mat& minus = pair.negative.image;
    CV_Assert((plus.type() == CV_8UC1 || plus.type() == CV_8UC3) && minus.type() == plus.type() &&
              minus.size() == plus.size() && handMask.type() == CV_8UC1 && handMask.size() == plus.size());
    const bool colour = plus.channels() == 3;
    clearPixels();
    if (!(widthPx > 0.0)) {
        evidence.clear(hypotheses());
        return;
    }
    const Eigen::Vector2d centre = tip - options_.centreBehindWidths * widthPx * direction;
    const double radius = options_.regionWidths * widthPx;
    const int x0 = std::max(1, static_cast<int>(std::floor(centre.x() - radius)));
    const int x1 = std::min(plus.cols - 2, static_cast<int>(std::ceil(centre.x() + radius)));
    const int y0 = std::max(1, static_cast<int>(std::floor(centre.y() - radius)));
    const int y1 = std::min(plus.rows - 2, static_cast<int>(std::ceil(centre.y() + radius)));
    const auto undistortedAt = [&](const Eigen::Vector2d& p) {
        const cv::Vec2f& u =
            undistorted_.at<cv::Vec2f>(std::clamp(static_cast<int>(std::lround(p.y())), 0, plus.rows - 1),
                                       std::clamp(static_cast<int>(std::lround(p.x())), 0, plus.cols - 1));
        return Eigen::Vector2d(u[0], u[1]);
    };
    // The fingertip's shape: a cap as wide as the finger around a centre half a width behind the tip, then
    // the finger, its cross-section an ellipse thicknessPerWidth as thick as wide. Each pixel sees it as
    // far below the top as the ellipse falls away at its distance from the axis (or from the cap's
    // centre), times the cosine of its ray's angle from the vertical.
    const double halfWidthPx = 0.5 * widthPx;
    const Eigen::Vector2d capCentre = tip - halfWidthPx * direction;
    const double alongMmPerPx =
        (onTable(undistortedAt(capCentre)) - onTable(undistortedAt(tip))).norm() / halfWidthPx;
    // The finger's section from the silhouette's width, the angle between the rays along its sides at the
    // distance of a finger resting there: seen obliquely, the table is foreshortened towards the camera and a
    // finger stands above it, so the table's scale neither along the finger nor across it gives its width.
    const Eigen::Vector2d across(-direction.y(), direction.x());
    const Eigen::Vector3d view = rayThrough(undistortedAt(capCentre)).normalized();
    const double apartRad = std::acos(
        std::clamp(rayThrough(undistortedAt(capCentre + halfWidthPx * across))
                       .normalized()
                       .dot(rayThrough(undistortedAt(capCentre - halfWidthPx * across)).normalized()),
                   -1.0, 1.0));
    const Eigen::Vector2d pointing = onTable(undistortedAt(tip)) - onTable(undistortedAt(capCentre));
    const double onTableHalfThicknessMm =
        fingerSection(view, pointing, 0.5 * apartRad * cameraCentre_.z() / std::abs(view.z()),
                      options_.thicknessPerWidth)
            .halfThicknessMm;
    const FingerSection section = fingerSection(
        view, pointing, 0.5 * apartRad * (cameraCentre_.z() - onTableHalfThicknessMm) / std::abs(view.z()),
        options_.thicknessPerWidth);
    const double halfThicknessMm = section.halfThicknessMm;
    const auto addShape = [&](int x, int y) {
        const Eigen::Vector2d offset = Eigen::Vector2d(x, y) - capCentre;
        const double behind = -offset.dot(direction);
        const double fromAxis =
            behind > 0.0 ? std::abs(offset.x() * direction.y() - offset.y() * direction.x()) : offset.norm();
        const double t = std::min(1.0, fromAxis / halfWidthPx);
        const double belowTopAlongView = halfThicknessMm * (1.0 - std::sqrt(1.0 - t * t));
        shape_.push_back({static_cast<float>(std::max(0.0, behind) * alongMmPerPx),
                          static_cast<float>(belowTopAlongView * verticalCosine(undistortedAt({x, y})))});
    };
    for (int y = y0; y <= y1; ++y) {
        const uchar* above = handMask.ptr<uchar>(y - 1);
        const uchar* m = handMask.ptr<uchar>(y);
        const uchar* below = handMask.ptr<uchar>(y + 1);
        for (int x = x0; x <= x1; ++x) {
            // Only pixels whose neighbours are hand too: a pixel on the outline sees some table, whose sharp
            // code would outweigh the skin's blurred one.
            if (!m[x] || !above[x] || !below[x] || !m[x - 1] || !m[x + 1] ||
                (x - centre.x()) * (x - centre.x()) + (y - centre.y()) * (y - centre.y()) > radius * radius)
                continue;
            addValue(colour ? channelSum<3, -1>(plus, minus, x, y) : channelSum<1, -1>(plus, minus, x, y), x,
                     y);
            addShape(x, y);
            if (options_.explainMotion)
                gradients_.push_back(colour ? textureGradient<3>(plus, minus, x, y)
                                            : textureGradient<1>(plus, minus, x, y));
        }
    }
    measurePixels(evidence);
    evidence.topAbovePadTimesPixels = evidence.pixels * section.topAbovePadMm;
}

Eigen::Vector3d SurfaceHeight::rayThrough(const Eigen::Vector2d& undistorted) const {
    return rayFromPixel_ * Eigen::Vector3d(undistorted.x(), undistorted.y(), 1.0);
}

double SurfaceHeight::verticalCosine(const Eigen::Vector2d& undistorted) const {
    const Eigen::Vector3d ray = rayThrough(undistorted);
    return std::abs(ray.z()) / ray.norm();
}

Eigen::Vector2d SurfaceHeight::onTable(const Eigen::Vector2d& undistorted) const {
    const Eigen::Vector3d ray = rayThrough(undistorted);
    if (std::abs(ray.z()) < 1e-12)
        return cameraCentre_.head<2>();
    return (cameraCentre_ - cameraCentre_.z() / ray.z() * ray).head<2>();
}

void SurfaceHeight::measurePixels(HeightEvidence& evidence, std::size_t stride) {
    const bool shaped = shape_.size() == values_.size();
    const std::size_t slopes = shaped ? slopeCount_ : 1;
    evidence.clear(heightCount_ * slopes);
    const std::size_t n = values_.size();
    if (n < 8)
        return;
    fitResiduals();
    double varianceS = 0.0;
    for (float r : residuals_)
        varianceS += r * r;
    evidence.subtractionVariance = varianceS;
    evidence.pixels = static_cast<double>(n);
    // Each pixel's ray through the candidate planes, as the projector sees it: a point on the table and a
    // step per candidate (homogeneous).
    rays_.clear();
    const double dStep = static_cast<double>(stride) * options_.stepMm;
    for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector3d ray = rayFromPixel_ * Eigen::Vector3d(points_[i].x, points_[i].y, 1.0);
        if (std::abs(ray.z()) < 1e-12) {
            rays_.addOutside();  // parallel to the table: no pixel of a fingertip
            continue;
        }
        const Eigen::Vector3d along = projectorRotation_ * ray / ray.z();
        rays_.add(epipole_ - cameraCentre_.z() * along, dStep * along);
    }
    // Every hypothesis samples the predicted code somewhere along each pixel's ray: a whole number of
    // candidate steps from the table plus the pixel's own extra steps for the shape and slope. The code is
    // sampled once per pixel at every whole step the hypotheses reach (its profile along the ray) and
    // interpolated between them, so that each hypothesis costs a blend instead of a projection.
    const std::size_t candidates = (heightCount_ + stride - 1) / stride;
    const auto extraSteps = [&](std::size_t slope, std::size_t i) {
        return shaped ? static_cast<float>((slopeOf(slope) * shape_[i].behindCapMm - shape_[i].belowTopMm) /
                                           dStep)
                      : 0.0f;
    };
    float lowest = 0.0f, highest = 0.0f;
    for (std::size_t slope = 0; slope < slopes; ++slope)
        for (std::size_t i = 0; i < n; ++i) {
            lowest = std::min(lowest, extraSteps(slope, i));
            highest = std::max(highest, extraSteps(slope, i));
        }
    const std::size_t padded = (candidates + kLanes - 1) / kLanes * kLanes;
    const int firstStep = static_cast<int>(std::floor(lowest));
    const std::size_t length =
        static_cast<std::size_t>(static_cast<int>(std::floor(highest)) - firstStep) + padded + 1;
    sampleProfiles(BilinearSampler(panel_), firstStep, length, profileSpacingSteps(firstStep, length));
    blendOffsets_.resize(n);
    blendWeights_.resize(n);
    for (std::size_t slope = 0; slope < slopes; ++slope) {
        for (std::size_t i = 0; i < n; ++i) {
            const float extra = extraSteps(slope, i);
            const float whole = std::floor(extra);
            blendOffsets_[i] = i * length + static_cast<std::size_t>(static_cast<int>(whole) - firstStep);
            blendWeights_[i] = extra - whole;
        }
        for (std::size_t k = 0; k < candidates; k += kLanes) {
            std::array<float, kLanes> values{}, squares{}, products{};
            accumulateBlends(k, values, squares, products);
            for (std::size_t lane = 0; lane < kLanes && k + lane < candidates; ++lane) {
                const std::size_t at = slope * heightCount_ + (k + lane) * stride;
                evidence.covariance[at] = products[lane];
                evidence.codeVariance[at] = std::max(
                    0.0, static_cast<double>(squares[lane]) -
                             static_cast<double>(values[lane]) * values[lane] / static_cast<double>(n));
            }
        }
    }
}

void SurfaceHeight::accumulateBlends(std::size_t candidate, std::array<float, kLanes>& values,
                                     std::array<float, kLanes>& squares,
                                     std::array<float, kLanes>& products) const {
    const std::size_t n = residuals_.size();
#if CV_SIMD128
    static_assert(kLanes == 4);
    cv::v_float32x4 sumValues = cv::v_setzero_f32(), sumSquares = sumValues, sumProducts = sumValues;
    for (std::size_t i = 0; i < n; ++i) {
        const float* at = profiles_.data() + blendOffsets_[i] + candidate;
        const cv::v_float32x4 low = cv::v_load(at), high = cv::v_load(at + 1);
        const cv::v_float32x4 value = cv::v_muladd(high - low, cv::v_setall_f32(blendWeights_[i]), low);
        sumValues += value;
        sumSquares = cv::v_muladd(value, value, sumSquares);
        sumProducts = cv::v_muladd(cv::v_setall_f32(residuals_[i]), value, sumProducts);
    }
    cv::v_store(values.data(), sumValues);
    cv::v_store(squares.data(), sumSquares);
    cv::v_store(products.data(), sumProducts);
#else
    for (std::size_t i = 0; i < n; ++i) {
        const float* at = profiles_.data() + blendOffsets_[i] + candidate;
        for (std::size_t lane = 0; lane < kLanes; ++lane) {
            const float value = at[lane] + blendWeights_[i] * (at[lane + 1] - at[lane]);
            values[lane] += value;
            squares[lane] += value * value;
            products[lane] += residuals_[i] * value;
        }
    }
#endif
}

std::size_t SurfaceHeight::profileSpacingSteps(int firstStep, std::size_t length) const {
    // The panel moves fastest per step where a ray is nearest the projector: at one end of its profile.
    float fastest = 0.0f;
    for (std::size_t i = 0; i < rays_.x.size(); ++i)
        for (const float steps : {static_cast<float>(firstStep), static_cast<float>(firstStep) + length}) {
            const float z = rays_.z[i] + steps * rays_.stepZ[i];
            const float x = rays_.x[i] + steps * rays_.stepX[i], y = rays_.y[i] + steps * rays_.stepY[i];
            const float moveX = rays_.stepX[i] * z - x * rays_.stepZ[i];
            const float moveY = rays_.stepY[i] * z - y * rays_.stepZ[i];
            fastest = std::max(fastest, std::hypot(moveX, moveY) / (z * z));
        }
    if (!(fastest > 0.0f) || profileSpacingPx_ / fastest >= static_cast<float>(length))
        return length;
    return std::max<std::size_t>(1, static_cast<std::size_t>(profileSpacingPx_ / fastest));
}

void SurfaceHeight::sampleProfiles(const BilinearSampler& sample, int firstStep, std::size_t length,
                                   std::size_t spacing) {
    const std::size_t n = residuals_.size();
    profiles_.resize(n * length);
    // Every `spacing` steps and the last one.
    const auto nextSample = [&](std::size_t j) {
        return j + 1 == length ? length : std::min(j + spacing, length - 1);
    };
    for (std::size_t j = 0; j < length; j = nextSample(j)) {
        const float steps = static_cast<float>(firstStep + static_cast<int>(j));
        std::size_t i = 0;
#if CV_SIMD128
        // Four pixels at a time: the positions, their division and the interpolation in vectors, only the
        // panel's reads one by one.
        const cv::v_float32x4 k = cv::v_setall_f32(steps);
        const cv::v_float32x4 zero = cv::v_setzero_f32();
        const cv::v_float32x4 lastX = cv::v_setall_f32(static_cast<float>(sample.lastX()));
        const cv::v_float32x4 lastY = cv::v_setall_f32(static_cast<float>(sample.lastY()));
        const cv::v_int32x4 rowStep = cv::v_setall_s32(static_cast<int>(sample.step()));
        alignas(16) int offsets[4];
        alignas(16) float result[4];
        for (; i + 4 <= n; i += 4) {
            const cv::v_float32x4 inverseZ =
                cv::v_setall_f32(1.0f) /
                cv::v_muladd(k, cv::v_load(&rays_.stepZ[i]), cv::v_load(&rays_.z[i]));
            cv::v_float32x4 x =
                cv::v_muladd(k, cv::v_load(&rays_.stepX[i]), cv::v_load(&rays_.x[i])) * inverseZ;
            cv::v_float32x4 y =
                cv::v_muladd(k, cv::v_load(&rays_.stepY[i]), cv::v_load(&rays_.y[i])) * inverseZ;
            const cv::v_float32x4 inside = (x >= zero) & (y >= zero) & (x < lastX) & (y < lastY);
            x = cv::v_select(inside, x, zero);
            y = cv::v_select(inside, y, zero);
            const cv::v_int32x4 x0 = cv::v_trunc(x), y0 = cv::v_trunc(y);
            const cv::v_float32x4 fx = x - cv::v_cvt_f32(x0), fy = y - cv::v_cvt_f32(y0);
            cv::v_store_aligned(offsets, y0 * rowStep + x0);
            const float* p0 = sample.data() + offsets[0];
            const float* p1 = sample.data() + offsets[1];
            const float* p2 = sample.data() + offsets[2];
            const float* p3 = sample.data() + offsets[3];
            const std::ptrdiff_t down = sample.step();
            const cv::v_float32x4 topLeft(p0[0], p1[0], p2[0], p3[0]), topRight(p0[1], p1[1], p2[1], p3[1]);
            const cv::v_float32x4 bottomLeft(p0[down], p1[down], p2[down], p3[down]);
            const cv::v_float32x4 bottomRight(p0[down + 1], p1[down + 1], p2[down + 1], p3[down + 1]);
            const cv::v_float32x4 top = cv::v_muladd(topRight - topLeft, fx, topLeft);
            const cv::v_float32x4 bottom = cv::v_muladd(bottomRight - bottomLeft, fx, bottomLeft);
            cv::v_store_aligned(
                result, cv::v_select(inside, cv::v_max(zero, cv::v_muladd(bottom - top, fy, top)), zero));
            for (std::size_t lane = 0; lane < 4; ++lane)
                profiles_[(i + lane) * length + j] = result[lane];
        }
#endif
        for (; i < n; ++i) {
            const float inverseZ = 1.0f / (rays_.z[i] + steps * rays_.stepZ[i]);
            profiles_[i * length + j] =
                std::max(0.0f, sample((rays_.x[i] + steps * rays_.stepX[i]) * inverseZ,
                                      (rays_.y[i] + steps * rays_.stepY[i]) * inverseZ));
        }
    }
    if (spacing == 1)
        return;
    // Between the samples, along each ray, the straight line.
    for (std::size_t i = 0; i < n; ++i) {
        float* profile = profiles_.data() + i * length;
        for (std::size_t j = 0, to = nextSample(0); to < length; j = to, to = nextSample(to)) {
            const float from = profile[j], slope = (profile[to] - from) / static_cast<float>(to - j);
            for (std::size_t t = 1; j + t < to; ++t)
                profile[j + t] = from + slope * static_cast<float>(t);
        }
    }
}

void SurfaceHeight::PanelRays::clear() {
    for (std::vector<float>* coordinate : {&x, &y, &z, &stepX, &stepY, &stepZ})
        coordinate->clear();
}

void SurfaceHeight::PanelRays::reserve(std::size_t pixels) {
    for (std::vector<float>* coordinate : {&x, &y, &z, &stepX, &stepY, &stepZ})
        coordinate->reserve(pixels);
}

void SurfaceHeight::PanelRays::add(const Eigen::Vector3d& onTable, const Eigen::Vector3d& step) {
    x.push_back(static_cast<float>(onTable.x()));
    y.push_back(static_cast<float>(onTable.y()));
    z.push_back(static_cast<float>(onTable.z()));
    stepX.push_back(static_cast<float>(step.x()));
    stepY.push_back(static_cast<float>(step.y()));
    stepZ.push_back(static_cast<float>(step.z()));
}

void SurfaceHeight::PanelRays::addOutside() {
    add(Eigen::Vector3d(-1.0, -1.0, 1.0), Eigen::Vector3d::Zero());
}

void SurfaceHeight::fitResiduals() {
    const std::size_t n = values_.size();
    residuals_.resize(n);
    // Least squares of S on (1, Tx, Ty) when the gradients were gathered, on 1 alone otherwise.
    const bool withGradients = gradients_.size() == n;
    const auto regressor = [&](std::size_t i) {
        return withGradients ? Eigen::Vector3d(1.0, gradients_[i].x, gradients_[i].y)
                             : Eigen::Vector3d(1.0, 0.0, 0.0);
    };
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector3d r = regressor(i);
        normal.noalias() += r * r.transpose();
        moment += r * static_cast<double>(values_[i]);
    }
    // A region of flat texture has no gradient to fit: a slight ridge keeps the system solvable and leaves
    // those coefficients at zero.
    const double ridge = 1e-6 * static_cast<double>(n) + 1e-9;
    normal(1, 1) += ridge;
    normal(2, 2) += ridge;
    const Eigen::Vector3d fit = normal.ldlt().solve(moment);
    for (std::size_t i = 0; i < n; ++i)
        residuals_[i] = static_cast<float>(values_[i] - regressor(i).dot(fit));
}

namespace {

// The evidence's correlation at each candidate height: at a given slope, interpolated between the two
// candidate slopes around it, or the best over its slopes.
class HeightProfile {
public:
    // slopeStep: between candidate slopes; slope: in the same unit, or nothing for the best.
    HeightProfile(const HeightEvidence& evidence, std::size_t heights, double slopeStep,
                  std::optional<double> slope)
        : evidence_(evidence), heights_(heights), rows_(evidence.codeVariance.size() / heights) {
        if (!slope || rows_ < 2)
            return;
        const double position = std::clamp(*slope / slopeStep, 0.0, static_cast<double>(rows_ - 1));
        row_ = std::min(static_cast<std::size_t>(position), rows_ - 2);
        weight_ = position - static_cast<double>(row_);
        atSlope_ = true;
    }

    bool measured(std::size_t h) const {
        if (atSlope_)
            return rowCorrelation(row_, h) || rowCorrelation(row_ + 1, h);
        for (std::size_t row = 0; row < rows_; ++row)
            if (rowCorrelation(row, h))
                return true;
        return false;
    }
    // -2 without evidence.
    double correlation(std::size_t h) const {
        if (atSlope_) {
            const std::optional<double> low = rowCorrelation(row_, h), high = rowCorrelation(row_ + 1, h);
            if (low && high)
                return (1.0 - weight_) * *low + weight_ * *high;
            return low ? *low : high ? *high : -2.0;
        }
        double best = -2.0;
        for (std::size_t row = 0; row < rows_; ++row)
            if (const std::optional<double> r = rowCorrelation(row, h))
                best = std::max(best, *r);
        return best;
    }

private:
    std::optional<double> rowCorrelation(std::size_t row, std::size_t h) const {
        const std::size_t at = row * heights_ + h;
        const double denominator = std::sqrt(evidence_.codeVariance[at] * evidence_.subtractionVariance);
        if (!(denominator > 0.0))
            return std::nullopt;
        return evidence_.covariance[at] / denominator;
    }

    const HeightEvidence& evidence_;
    std::size_t heights_;
    std::size_t rows_;
    bool atSlope_ = false;
    std::size_t row_ = 0;
    double weight_ = 0.0;
};

}  // namespace

bool SurfaceHeight::favoursPadUpTo(const HeightEvidence& evidence, double padHeightMm,
                                   std::optional<double> slope) const {
    if (evidence.covariance.size() < heightCount_ || evidence.pixels < 8 ||
        evidence.subtractionVariance <= 0.0)
        return false;
    const HeightProfile profile(evidence, heightCount_, options_.slopeStep, slope);
    const double heightMm = padHeightMm + evidence.topAbovePadTimesPixels / evidence.pixels;
    double below = -2.0, above = -2.0;
    for (std::size_t h = 0; h < heightCount_; ++h) {
        double& side = heightOf(h) <= heightMm ? below : above;
        side = std::max(side, profile.correlation(h));
    }
    return below > above && below >= options_.significance * std::sqrt(2.0 / evidence.pixels);
}

void SurfaceHeight::supportSlopes(const HeightEvidence& evidence, SlopeSupport& support) const {
    const std::size_t rows = heightCount_ == 0 ? 0 : evidence.codeVariance.size() / heightCount_;
    support.clear(rows);
    if (evidence.pixels < 8 || evidence.subtractionVariance <= 0.0)
        return;
    for (std::size_t row = 0; row < rows; ++row) {
        const HeightProfile profile(evidence, heightCount_, options_.slopeStep,
                                    static_cast<double>(row) * options_.slopeStep);
        double best = 0.0;
        for (std::size_t h = 0; h < heightCount_; ++h)
            best = std::max(best, profile.correlation(h));
        support.logLikelihood[row] = 0.25 * evidence.pixels * best * best;
    }
}

double SurfaceHeight::bestSlope(const SlopeSupport& support) const {
    const std::vector<double>& l = support.logLikelihood;
    if (l.empty())
        return 0.0;
    const std::size_t best = static_cast<std::size_t>(std::max_element(l.begin(), l.end()) - l.begin());
    double offset = 0.0;
    if (best > 0 && best + 1 < l.size()) {
        const double curvature = l[best - 1] - 2.0 * l[best] + l[best + 1];
        if (curvature < 0.0)
            offset = std::clamp(0.5 * (l[best - 1] - l[best + 1]) / curvature, -0.5, 0.5);
    }
    return (static_cast<double>(best) + offset) * options_.slopeStep;
}

HeightEstimate SurfaceHeight::estimate(const HeightEvidence& evidence, std::optional<double> slope) const {
    HeightEstimate result;
    const std::size_t count = heightCount_;
    if (count == 0 || evidence.covariance.size() < count || evidence.pixels < 8 ||
        evidence.subtractionVariance <= 0.0)
        return result;
    const HeightProfile profile(evidence, count, options_.slopeStep, slope);
    std::size_t best = 0;
    double bestCorrelation = -2.0;
    for (std::size_t h = 0; h < count; ++h)
        if (const double r = profile.correlation(h); r > bestCorrelation) {
            bestCorrelation = r;
            best = h;
        }
    // Chance correlation over the region: neighbouring pixels share light through the blurs, about two
    // pixels per independent sample.
    const double chance = std::sqrt(2.0 / evidence.pixels);
    result.correlation = bestCorrelation;
    if (bestCorrelation < options_.significance * chance)
        return result;
    // A best height at the top of the range is no peak: the surface lies higher or the correlation rises
    // for another reason (a region reaching onto the hand further up), and nothing says how high. The
    // bottom of the range is the table, below which nothing lies.
    if (best + 1 == count)
        return result;
    // Another peak about as high makes the height ambiguous: the faint code on a small region of skin can
    // match itself at a second height by chance. The runner-up is the best correlation beyond where the
    // curve falls to half the best on either side.
    // Heights without evidence (a coarse look) are stepped over.
    const double half = 0.5 * bestCorrelation;
    const auto withinPeak = [&](std::size_t h) {
        return !profile.measured(h) || profile.correlation(h) > half;
    };
    std::size_t low = best, high = best;
    while (low > 0 && withinPeak(low))
        --low;
    while (high + 1 < count && withinPeak(high))
        ++high;
    double runnerUp = -1.0;
    for (std::size_t h = 0; h < count; ++h)
        if ((h < low || h > high) && profile.measured(h))
            runnerUp = std::max(runnerUp, profile.correlation(h));
    // Two correlations of chance differ by sqrt(2) times one's deviation.
    if (bestCorrelation - runnerUp < options_.distinctness * std::sqrt(2.0) * chance)
        return result;
    // The peak to a fraction of a step: the parabola through the best height and its neighbours.
    double offset = 0.0;
    if (best > 0 && best + 1 < count && profile.measured(best - 1) && profile.measured(best + 1)) {
        const double a = profile.correlation(best - 1), b = bestCorrelation,
                     c = profile.correlation(best + 1);
        const double curvature = a - 2 * b + c;
        if (curvature < 0.0)
            offset = std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5);
    }
    result.valid = true;
    result.heightMm = (static_cast<double>(best) + offset) * options_.stepMm;
    result.padHeightMm = result.heightMm - evidence.topAbovePadTimesPixels / evidence.pixels;
    // The peak's width in height over its height above chance: a sharp, strong peak pins the height down.
    result.uncertaintyMm = options_.stepMm * chance / std::max(bestCorrelation, chance) * 4.0;
    return result;
}

}  // namespace everytouch::core
