#include "core/pair_calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>
#include <unsupported/Eigen/LevenbergMarquardt>

#include "core/geometry.h"
#include "core/plane_triangulation.h"

namespace everytouch::core {

namespace {

// Parameter vector: the pair, then each view's surface.
//   0-3   camera fx fy cx cy          4-5   camera k1 k2
//   6-9   projector fx fy cx cy       10-12 camera -> projector rotation vector   13-15 translation, mm
//   per view with the rectangle: its rotation vector and translation into the camera frame (6);
//   per view without: the plane m . X = 1 (m = normal / distance, 1/mm) (3).
constexpr int kPairParameters = 16;

// Parameter magnitudes that set the numerical derivatives' steps.
double typicalMagnitude(int parameter, bool rectangleView, int viewParameter) {
    if (parameter < 4 || (parameter >= 6 && parameter < 10))
        return 1000.0;  // pixels
    if (parameter < 13)
        return 1.0;  // distortion coefficients, radians
    if (parameter < kPairParameters)
        return 100.0;  // mm
    if (rectangleView)
        return viewParameter < 3 ? 1.0 : 500.0;
    return 1.0 / 500.0;
}

// The least squares moves the free parameters; with square pixels each device's fy is its fx and not free.
class ParameterLayout {
public:
    ParameterLayout(bool squarePixels, int fullCount) {
        for (int parameter = 0; parameter < fullCount; ++parameter)
            if (!squarePixels || (parameter != 1 && parameter != 7))
                freeToFull_.push_back(parameter);
        expansion_ = Eigen::MatrixXd::Zero(fullCount, freeCount());
        for (int free = 0; free < freeCount(); ++free)
            expansion_(freeToFull_[free], free) = 1.0;
        if (squarePixels) {
            expansion_(1, 0) = 1.0;  // camera fy = fx
            expansion_(7, 5) = 1.0;  // projector fy = fx
        }
    }

    int freeCount() const { return static_cast<int>(freeToFull_.size()); }
    // The full parameter a free one stands for (the first of those it sets).
    int fullIndex(int free) const { return freeToFull_[free]; }
    Eigen::VectorXd expand(const Eigen::VectorXd& free) const { return expansion_ * free; }
    Eigen::VectorXd reduce(const Eigen::VectorXd& full) const {
        Eigen::VectorXd free(freeCount());
        for (int index = 0; index < freeCount(); ++index)
            free(index) = full(freeToFull_[index]);
        return free;
    }
    const Eigen::MatrixXd& expansion() const { return expansion_; }

private:
    std::vector<int> freeToFull_;
    Eigen::MatrixXd expansion_;  // full = expansion * free
};

Eigen::Matrix3d intrinsics(const double* parameters) {
    Eigen::Matrix3d matrix;
    matrix << parameters[0], 0, parameters[2], 0, parameters[1], parameters[3], 0, 0, 1;
    return matrix;
}

ProjectorCameraPair pairFromParameters(const Eigen::VectorXd& parameters,
                                       const PairCalibrationOptions& options) {
    ProjectorCameraPair pair;
    pair.cameraSize = options.cameraSize;
    pair.projectorSize = options.projectorSize;
    pair.camera.matrix = intrinsics(parameters.data());
    pair.camera.distortion << parameters(4), parameters(5), 0, 0, 0;
    pair.projectorMatrix = intrinsics(parameters.data() + 6);
    pair.cameraToProjector.linear() = rotationFromVector(parameters.segment<3>(10));
    pair.cameraToProjector.translation() = parameters.segment<3>(13);
    return pair;
}

Eigen::Isometry3d poseFromParameters(const double* parameters) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = rotationFromVector(Eigen::Map<const Eigen::Vector3d>(parameters));
    pose.translation() = Eigen::Map<const Eigen::Vector3d>(parameters + 3);
    return pose;
}

Eigen::Hyperplane<double, 3> planeFromInverseDepth(const Eigen::Vector3d& m) {
    return Eigen::Hyperplane<double, 3>(m.normalized(), -1.0 / m.norm());
}

Eigen::Vector3d inverseDepthOf(const Eigen::Hyperplane<double, 3>& plane) {
    return plane.normal() / -plane.offset();
}

class PairResiduals : public Eigen::DenseFunctor<double> {
public:
    PairResiduals(const std::vector<PlaneView>& views, const PairCalibrationOptions& options,
                  const ParameterLayout& layout, int residuals)
        : Eigen::DenseFunctor<double>(layout.freeCount(), residuals),
          views_(&views),
          options_(&options),
          layout_(&layout) {
        int parameter = kPairParameters, residual = 0;
        for (const PlaneView& view : views) {
            parameterOffsets_.push_back(parameter);
            residualOffsets_.push_back(residual);
            parameter += view.rectangleCorners ? 6 : 3;
            residual += residualCount(view);
        }
    }

    int operator()(const Eigen::VectorXd& free, Eigen::VectorXd& residuals) const {
        const Eigen::VectorXd parameters = layout_->expand(free);
        const ProjectorCameraPair pair = pairFromParameters(parameters, *options_);
        for (size_t view = 0; view < views_->size(); ++view)
            evaluateView(pair, parameters, view, residuals.data() + residualOffsets_[view]);
        return 0;
    }

    // Forward differences, exploiting that a view's surface parameters touch only that view's residuals.
    int df(const Eigen::VectorXd& free, Eigen::MatrixXd& jacobian) const {
        Eigen::VectorXd base(values()), moved(values());
        (*this)(free, base);
        jacobian.setZero(values(), inputs());
        const Eigen::VectorXd parameters = layout_->expand(free);
        const ProjectorCameraPair pair = pairFromParameters(parameters, *options_);
        Eigen::VectorXd shifted = free;
        for (int index = 0; index < inputs(); ++index) {
            const int full = layout_->fullIndex(index);
            const int view = viewOf(full);
            const bool rectangleView = view >= 0 && (*views_)[view].rectangleCorners.has_value();
            const double step = std::sqrt(std::numeric_limits<double>::epsilon()) *
                                std::max(std::abs(free(index)),
                                         typicalMagnitude(full, rectangleView,
                                                          view >= 0 ? full - parameterOffsets_[view] : 0));
            shifted(index) = free(index) + step;
            if (view < 0) {
                (*this)(shifted, moved);
                jacobian.col(index) = (moved - base) / step;
            } else {
                const int first = residualOffsets_[view], count = residualCount((*views_)[view]);
                Eigen::VectorXd surface = parameters;
                surface(full) = shifted(index);
                evaluateView(pair, surface, view, moved.data() + first);
                jacobian.col(index).segment(first, count) =
                    (moved.segment(first, count) - base.segment(first, count)) / step;
            }
            shifted(index) = free(index);
        }
        return 0;
    }

    int parameterOffset(size_t view) const { return parameterOffsets_[view]; }

private:
    // The view a full parameter belongs to; -1 for the pair's parameters.
    int viewOf(int parameter) const {
        if (parameter < kPairParameters)
            return -1;
        const auto next = std::upper_bound(parameterOffsets_.begin(), parameterOffsets_.end(), parameter);
        return static_cast<int>(next - parameterOffsets_.begin()) - 1;
    }

    void evaluateView(const ProjectorCameraPair& pair, const Eigen::VectorXd& parameters, size_t view,
                      double* residuals) const {
        const PlaneView& planeView = (*views_)[view];
        const double* surface = parameters.data() + parameterOffsets_[view];
        if (planeView.rectangleCorners) {
            const Eigen::Isometry3d rectangleToCamera = poseFromParameters(surface);
            planeViewResiduals(pair, planeOf(rectangleToCamera), planeView, rectangleToCamera,
                               options_->rectangleSizeMm, residuals);
        } else {
            planeViewResiduals(pair, planeFromInverseDepth(Eigen::Map<const Eigen::Vector3d>(surface)),
                               planeView, Eigen::Isometry3d::Identity(), options_->rectangleSizeMm,
                               residuals);
        }
    }

    const std::vector<PlaneView>* views_;
    const PairCalibrationOptions* options_;
    const ParameterLayout* layout_;
    std::vector<int> parameterOffsets_;
    std::vector<int> residualOffsets_;
};

std::vector<Eigen::Vector2d> rectangleModel(cv::Size2d sizeMm) {
    return {{0, 0}, {sizeMm.width, 0}, {sizeMm.width, sizeMm.height}, {0, sizeMm.height}};
}

// Focal length from the rectangles' homographies (rectangle mm -> raw camera pixels) with the principal point
// at `centre` and square pixels: Zhang's two constraints per view, r1 . r2 = 0 and |r1| = |r2|, in 1 / f^2.
std::optional<double> focalFromRectangles(const std::vector<Eigen::Matrix3d>& homographies,
                                          const Eigen::Vector2d& centre) {
    double numerator = 0.0, denominator = 0.0;
    Eigen::Matrix3d shift = Eigen::Matrix3d::Identity();
    shift.block<2, 1>(0, 2) = -centre;
    for (const Eigen::Matrix3d& homography : homographies) {
        const Eigen::Matrix3d h = shift * homography;
        const double a1 = h(0, 0) * h(0, 1) + h(1, 0) * h(1, 1), b1 = h(2, 0) * h(2, 1);
        const double a2 = h(0, 0) * h(0, 0) + h(1, 0) * h(1, 0) - h(0, 1) * h(0, 1) - h(1, 1) * h(1, 1);
        const double b2 = h(2, 0) * h(2, 0) - h(2, 1) * h(2, 1);
        numerator -= a1 * b1 + a2 * b2;
        denominator += a1 * a1 + a2 * a2;
    }
    const double inverseSquare = numerator / denominator;
    if (!(inverseSquare > 0))
        return std::nullopt;
    return 1.0 / std::sqrt(inverseSquare);
}

// The rectangle's frame in the camera frame from its homography and the camera matrix (Zhang).
Eigen::Isometry3d poseFromHomography(const Eigen::Matrix3d& homography, const Eigen::Matrix3d& cameraMatrix) {
    const Eigen::Matrix3d normalised = cameraMatrix.inverse() * homography;
    const double scale = 2.0 / (normalised.col(0).norm() + normalised.col(1).norm());
    Eigen::Matrix3d rotation;
    rotation.col(0) = normalised.col(0) * scale;
    rotation.col(1) = normalised.col(1) * scale;
    Eigen::Vector3d translation = normalised.col(2) * scale;
    if (translation.z() < 0) {
        rotation.leftCols<2>() *= -1.0;
        translation *= -1.0;
    }
    rotation.col(2) = rotation.col(0).cross(rotation.col(1));
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(rotation, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = svd.matrixU() * svd.matrixV().transpose();
    pose.translation() = translation;
    return pose;
}

Eigen::Isometry3d toIsometry(const cv::Mat& rotationVector, const cv::Mat& translation) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = rotationFromVector(
        {rotationVector.at<double>(0), rotationVector.at<double>(1), rotationVector.at<double>(2)});
    pose.translation() << translation.at<double>(0), translation.at<double>(1), translation.at<double>(2);
    return pose;
}

// The closed-form start of the minimisation: every parameter of the layout `residuals` uses.
Result<Eigen::VectorXd> initialEstimate(const std::vector<PlaneView>& views,
                                        const PairCalibrationOptions& options, int parameterCount,
                                        const PairResiduals& residuals) {
    // Camera: principal point at the centre, focal length from the rectangles, no distortion.
    const Eigen::Vector2d centre((options.cameraSize.width - 1) / 2.0, (options.cameraSize.height - 1) / 2.0);
    const std::vector<Eigen::Vector2d> model = rectangleModel(options.rectangleSizeMm);
    std::vector<Eigen::Matrix3d> homographies;
    for (const PlaneView& view : views)
        if (view.rectangleCorners)
            homographies.push_back(
                fitHomography(model, {view.rectangleCorners->begin(), view.rectangleCorners->end()}));
    // A rectangle seen nearly head-on says little about the focal length; a typical lens then is a better
    // start.
    const double fallbackFocal = static_cast<double>(options.cameraSize.width);
    double focal = focalFromRectangles(homographies, centre).value_or(fallbackFocal);
    if (focal < 0.3 * fallbackFocal || focal > 10.0 * fallbackFocal)
        focal = fallbackFocal;
    ProjectorCameraPair pair;
    pair.cameraSize = options.cameraSize;
    pair.projectorSize = options.projectorSize;
    pair.camera.matrix << focal, 0, centre.x(), 0, focal, centre.y(), 0, 0, 1;

    // Each rectangle's surface from its homography; the correspondences on it become points of known metric
    // position there, which calibrate the projector like a camera looking at a flat target.
    std::vector<Eigen::Isometry3d> rectanglePoses;
    std::vector<std::vector<cv::Point3f>> objectPoints;
    std::vector<std::vector<cv::Point2f>> imagePoints;
    for (size_t view = 0, rectangle = 0; view < views.size(); ++view) {
        if (!views[view].rectangleCorners)
            continue;
        const Eigen::Isometry3d pose = poseFromHomography(homographies[rectangle++], pair.camera.matrix);
        rectanglePoses.push_back(pose);
        const Eigen::Isometry3d cameraToRectangle = pose.inverse();
        const Eigen::Hyperplane<double, 3> plane = planeOf(pose);
        std::vector<cv::Point3f> object;
        std::vector<cv::Point2f> image;
        for (size_t index = 0; index < views[view].cameraPoints.size(); ++index) {
            const Eigen::Vector3d onSurface =
                cameraToRectangle * pair.planePointOfCameraPixel(views[view].cameraPoints[index], plane);
            object.emplace_back(static_cast<float>(onSurface.x()), static_cast<float>(onSurface.y()), 0.0f);
            image.emplace_back(static_cast<float>(views[view].projectorPoints[index].x()),
                               static_cast<float>(views[view].projectorPoints[index].y()));
        }
        objectPoints.push_back(std::move(object));
        imagePoints.push_back(std::move(image));
    }
    cv::Mat projectorMatrix, projectorDistortion;
    std::vector<cv::Mat> rotations, translations;
    try {
        cv::calibrateCamera(
            objectPoints, imagePoints, options.projectorSize, projectorMatrix, projectorDistortion, rotations,
            translations,
            cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3);
    } catch (const cv::Exception& error) {
        return Failure{std::string("initial projector estimate failed: ") + error.what()};
    }
    for (int row = 0; row < 3; ++row)
        for (int column = 0; column < 3; ++column)
            pair.projectorMatrix(row, column) = projectorMatrix.at<double>(row, column);

    // Camera -> projector: the mean over the rectangle views of projector-from-rectangle after
    // rectangle-from-camera.
    Eigen::Vector4d quaternionSum = Eigen::Vector4d::Zero();
    Eigen::Vector3d translationSum = Eigen::Vector3d::Zero();
    for (size_t index = 0; index < rectanglePoses.size(); ++index) {
        const Eigen::Isometry3d cameraToProjector =
            toIsometry(rotations[index], translations[index]) * rectanglePoses[index].inverse();
        Eigen::Vector4d quaternion = Eigen::Quaterniond(cameraToProjector.rotation()).coeffs();
        if (quaternionSum.dot(quaternion) < 0)
            quaternion = -quaternion;
        quaternionSum += quaternion;
        translationSum += cameraToProjector.translation();
    }
    pair.cameraToProjector.linear() = Eigen::Quaterniond(quaternionSum.normalized()).toRotationMatrix();
    pair.cameraToProjector.translation() = translationSum / static_cast<double>(rectanglePoses.size());

    Eigen::VectorXd parameters = Eigen::VectorXd::Zero(parameterCount);
    parameters.head<4>() << focal, focal, centre.x(), centre.y();
    parameters.segment<4>(6) << pair.projectorMatrix(0, 0), pair.projectorMatrix(1, 1),
        pair.projectorMatrix(0, 2), pair.projectorMatrix(1, 2);
    parameters.segment<3>(10) = vectorFromRotation(pair.cameraToProjector.rotation());
    parameters.segment<3>(13) = pair.cameraToProjector.translation();
    for (size_t view = 0, rectangle = 0; view < views.size(); ++view) {
        const int offset = residuals.parameterOffset(view);
        if (views[view].rectangleCorners) {
            const Eigen::Isometry3d& pose = rectanglePoses[rectangle++];
            parameters.segment<3>(offset) = vectorFromRotation(pose.rotation());
            parameters.segment<3>(offset + 3) = pose.translation();
            continue;
        }
        const std::optional<Eigen::Hyperplane<double, 3>> plane = triangulatePlane(pair, views[view]);
        if (!plane)
            return Failure{"view " + std::to_string(view + 1) +
                           ": its correspondences do not triangulate to a plane in front of the camera"};
        parameters.segment<3>(offset) = inverseDepthOf(*plane);
    }
    return parameters;
}

// Every n-th correspondence, so that at most `limit` remain.
PlaneView thinned(const PlaneView& view, int limit) {
    const size_t count = view.cameraPoints.size();
    if (static_cast<int>(count) <= limit)
        return view;
    PlaneView kept;
    kept.rectangleCorners = view.rectangleCorners;
    for (int index = 0; index < limit; ++index) {
        const size_t source = index * count / limit;
        kept.cameraPoints.push_back(view.cameraPoints[source]);
        kept.projectorPoints.push_back(view.projectorPoints[source]);
    }
    return kept;
}

PairUncertainty uncertaintyOf(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& residuals,
                              const ParameterLayout& layout) {
    PairUncertainty uncertainty;
    const Eigen::Index degreesOfFreedom = jacobian.rows() - jacobian.cols();
    if (degreesOfFreedom <= 0)
        return uncertainty;
    const double variance = residuals.squaredNorm() / static_cast<double>(degreesOfFreedom);
    // Scaled to unit columns so that millimetres, pixels and radians compare; a direction the views do not
    // determine shows as an infinite deviation instead of being dropped as a pseudo-inverse would.
    const Eigen::VectorXd scale = jacobian.colwise().norm().cwiseMax(1e-300).cwiseInverse();
    const Eigen::MatrixXd scaled = jacobian * scale.asDiagonal();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinV);
    const Eigen::VectorXd inverseSquares = svd.singularValues().cwiseAbs2().cwiseInverse();
    const Eigen::MatrixXd freeCovariance = variance * scale.asDiagonal() * svd.matrixV() *
                                           inverseSquares.asDiagonal() * svd.matrixV().transpose() *
                                           scale.asDiagonal();
    const Eigen::MatrixXd covariance = layout.expansion() * freeCovariance * layout.expansion().transpose();
    const Eigen::VectorXd deviation = covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    uncertainty.camera = deviation.head<4>();
    uncertainty.distortion = deviation.segment<2>(4);
    uncertainty.projector = deviation.segment<4>(6);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> rotation(covariance.block<3, 3>(10, 10));
    uncertainty.rotationDeg = std::sqrt(std::max(0.0, rotation.eigenvalues().maxCoeff())) * 180.0 / M_PI;
    uncertainty.translationMm = deviation.segment<3>(13);
    return uncertainty;
}

}  // namespace

std::optional<std::string> PairCalibrationOptions::validate() const {
    if (cameraSize.width <= 0 || cameraSize.height <= 0)
        return "camera_size: width and height must be positive";
    if (projectorSize.width <= 0 || projectorSize.height <= 0)
        return "projector_size: width and height must be positive";
    if (!(rectangleSizeMm.width > 0) || !(rectangleSizeMm.height > 0))
        return "rectangle size_mm: both sides must be positive";
    if (maxPointsPerView < 8)
        return "max_points_per_view: must be at least 8";
    if (!(maxRmsPx > 0))
        return "max_rms_px: must be positive";
    return std::nullopt;
}

Result<PairCalibration> calibrateProjectorCameraPair(const std::vector<PlaneView>& views,
                                                     const PairCalibrationOptions& options) {
    if (auto problem = options.validate())
        throw std::invalid_argument("PairCalibrationOptions: " + *problem);
    PairCalibration calibration;
    std::vector<PlaneView> used;
    int rectangleViews = 0;
    for (size_t view = 0; view < views.size(); ++view) {
        if (views[view].cameraPoints.size() != views[view].projectorPoints.size() ||
            views[view].cameraPoints.size() < 8)
            return Failure{"view " + std::to_string(view + 1) +
                           ": need at least 8 camera <-> projector correspondences, as many of each"};
        used.push_back(thinned(views[view], options.maxPointsPerView));
        rectangleViews += views[view].rectangleCorners ? 1 : 0;
    }
    constexpr int kMinRectangleViews = 3;
    if (rectangleViews < kMinRectangleViews)
        return Failure{"the rectangle lies on " + std::to_string(rectangleViews) +
                       " of the views; it must lie on at least 3 differently tilted surfaces"};

    int parameterCount = kPairParameters, residualTotal = 0;
    for (const PlaneView& view : used) {
        parameterCount += view.rectangleCorners ? 6 : 3;
        residualTotal += residualCount(view);
    }
    const ParameterLayout layout(options.squarePixels, parameterCount);
    PairResiduals residuals(used, options, layout, residualTotal);
    const Result<Eigen::VectorXd> initial = initialEstimate(used, options, parameterCount, residuals);
    if (!initial.ok())
        return initial.failure();

    Eigen::VectorXd free = layout.reduce(initial.value());
    Eigen::LevenbergMarquardt<PairResiduals> solver(residuals);
    solver.setMaxfev(1000);
    solver.setXtol(1e-12);
    solver.setFtol(1e-12);
    const Eigen::LevenbergMarquardtSpace::Status status = solver.minimize(free);
    calibration.iterations = static_cast<int>(solver.iterations());

    const Eigen::VectorXd parameters = layout.expand(free);
    Eigen::VectorXd finalResiduals(residualTotal);
    residuals(free, finalResiduals);
    calibration.rmsPx = reprojectionRms(used, finalResiduals);
    calibration.pair = pairFromParameters(parameters, options);
    for (size_t view = 0; view < used.size(); ++view) {
        const int offset = residuals.parameterOffset(view);
        calibration.planes.push_back(used[view].rectangleCorners
                                         ? planeOf(poseFromParameters(parameters.data() + offset))
                                         : planeFromInverseDepth(parameters.segment<3>(offset)));
    }
    Eigen::MatrixXd jacobian;
    residuals.df(free, jacobian);
    calibration.standardDeviation = uncertaintyOf(jacobian, finalResiduals, layout);

    if (status == Eigen::LevenbergMarquardtSpace::ImproperInputParameters || !finalResiduals.allFinite())
        return Failure{"the least squares did not run: the initial estimate is not usable"};
    // Rectangles on parallel surfaces carry the same metric information over and over.
    double widestTiltDeg = 0.0;
    for (size_t first = 0; first < used.size(); ++first)
        for (size_t second = first + 1; second < used.size(); ++second)
            if (used[first].rectangleCorners && used[second].rectangleCorners)
                widestTiltDeg =
                    std::max(widestTiltDeg, std::acos(std::clamp(calibration.planes[first].normal().dot(
                                                                     calibration.planes[second].normal()),
                                                                 -1.0, 1.0)) *
                                                180.0 / M_PI);
    constexpr double kMinTiltDeg = 10.0;
    if (widestTiltDeg < kMinTiltDeg) {
        char message[160];
        std::snprintf(
            message, sizeof message,
            "the surfaces carrying the rectangle differ in tilt by %.1f degrees at most; tilt the board "
            "by %.0f degrees or more in different directions",
            widestTiltDeg, kMinTiltDeg);
        return Failure{message};
    }
    if (!(calibration.rmsPx.all <= options.maxRmsPx)) {
        char message[200];
        std::snprintf(
            message, sizeof message,
            "RMS reprojection error %.2f px exceeds %.2f px (camera %.2f, projector %.2f): views of "
            "surfaces that are not flat, or correspondences that are wrong",
            calibration.rmsPx.all, options.maxRmsPx, calibration.rmsPx.camera, calibration.rmsPx.projector);
        return Failure{message};
    }
    return calibration;
}

}  // namespace everytouch::core
