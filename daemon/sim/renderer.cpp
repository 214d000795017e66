#include "sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "core/embedding.h"
#include "core/geometry.h"

namespace everytouch::sim {

namespace {

constexpr float kNoHit = std::numeric_limits<float>::infinity();
constexpr float kShadowBiasMm = 2.0f;  // a surface point is shadowed by hand parts at least this much nearer
constexpr double kTexelMm = 0.4;       // resolution of the table's albedo map

// Linear reflectance (R, G, B) of skin tones and of finger nails over them.
Eigen::Vector3f skinReflectance(SkinTone tone) {
    switch (tone) {
        case SkinTone::Light:
            return {0.62f, 0.45f, 0.36f};
        case SkinTone::Medium:
            return {0.50f, 0.34f, 0.25f};
        case SkinTone::Tan:
            return {0.38f, 0.25f, 0.16f};
        case SkinTone::Dark:
            return {0.20f, 0.12f, 0.08f};
    }
    return {0.5f, 0.34f, 0.25f};
}

Eigen::Vector3f toBgr(const Eigen::Vector3f& rgb) {
    return {rgb.z(), rgb.y(), rgb.x()};
}

// Bilinear sample of a float image with `channels` channels; false outside.
template <int channels>
bool sampleBilinear(const cv::Mat& image, float x, float y, float* out) {
    if (!(x >= 0.0f && y >= 0.0f && x <= image.cols - 1.001f && y <= image.rows - 1.001f))
        return false;
    const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
    const float fx = x - x0, fy = y - y0;
    const float* row0 = image.ptr<float>(y0) + x0 * channels;
    const float* row1 = image.ptr<float>(y0 + 1) + x0 * channels;
    for (int c = 0; c < channels; ++c) {
        const float top = row0[c] + (row0[c + channels] - row0[c]) * fx;
        const float bottom = row1[c] + (row1[c + channels] - row1[c]) * fx;
        out[c] = top + (bottom - top) * fy;
    }
    return true;
}

// Image region containing a capsule: the union of the discs its two end spheres project to (a sphere swept
// along the axis stays inside their convex hull). Conservative for off-axis spheres, whose images stretch.
cv::Rect capsuleBox(const Capsule& capsule, const Eigen::Matrix3d& intrinsics,
                    const Eigen::Isometry3d& tableToDevice, cv::Size image) {
    const double radius = capsule.axes.colwise().norm().maxCoeff();
    const double focal = std::max(intrinsics(0, 0), intrinsics(1, 1));
    double minX = 1e18, minY = 1e18, maxX = -1e18, maxY = -1e18;
    for (const Eigen::Vector3d& centre : {capsule.origin, capsule.axisEnd()}) {
        const Eigen::Vector3d inDevice = tableToDevice * centre;
        if (inDevice.z() - radius < 1.0)
            return cv::Rect(0, 0, image.width, image.height);
        const Eigen::Vector3d q = intrinsics * inDevice;
        const double reach = 1.2 * radius * focal / (inDevice.z() - radius) + 1.0;
        minX = std::min(minX, q.x() / q.z() - reach), maxX = std::max(maxX, q.x() / q.z() + reach);
        minY = std::min(minY, q.y() / q.z() - reach), maxY = std::max(maxY, q.y() / q.z() + reach);
    }
    const cv::Rect box(static_cast<int>(std::floor(minX)), static_cast<int>(std::floor(minY)),
                       static_cast<int>(std::ceil(maxX - minX)) + 2,
                       static_cast<int>(std::ceil(maxY - minY)) + 2);
    return box & cv::Rect(0, 0, image.width, image.height);
}

double jacobianScale(const Eigen::Matrix3d& homography, const Eigen::Vector2d& at) {
    const double step = 0.5;
    const Eigen::Vector2d dx = core::applyHomography(homography, at + Eigen::Vector2d(step, 0)) -
                               core::applyHomography(homography, at - Eigen::Vector2d(step, 0));
    const Eigen::Vector2d dy = core::applyHomography(homography, at + Eigen::Vector2d(0, step)) -
                               core::applyHomography(homography, at - Eigen::Vector2d(0, step));
    return std::sqrt(std::abs(dx.x() * dy.y() - dx.y() * dy.x())) / (2 * step);
}

void blurIfNeeded(const cv::Mat& in, cv::Mat& out, double sigma) {
    if (sigma > 0.05) {
        const int reach = static_cast<int>(std::ceil(3.0 * sigma));
        cv::GaussianBlur(in, out, {2 * reach + 1, 2 * reach + 1}, sigma, sigma, cv::BORDER_REPLICATE);
    } else {
        in.copyTo(out);
    }
}

cv::Mat toCv(const Eigen::Matrix3d& m) {
    cv::Mat out(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            out.at<double>(r, c) = m(r, c);
    return out;
}

}  // namespace

Renderer::Renderer(const SimParameters& parameters, const core::Calibration& calibration,
                   const cv::Mat& pattern)
    : parameters_(parameters),
      calibration_(calibration),
      pattern_(pattern.clone()),
      sensor_(parameters, calibration) {
    CV_Assert(pattern.type() == CV_8UC1 && pattern.size() == calibration.projectorSize);
    const SimParameters& p = parameters_;
    const cv::Size cameraSize = calibration.cameraSize, panelSize = calibration.projectorSize;
    cameraCentre_ = calibration.tableToCamera.inverse().translation();
    projectorCentre_ = calibration.tableToProjector.inverse().translation();
    cameraPixelToRay_ = calibration.tableToCamera.rotation().transpose() * calibration.cameraMatrix.inverse();
    projectorPixelToRay_ =
        calibration.tableToProjector.rotation().transpose() * calibration.projectorMatrix.inverse();
    projectorProjection_ =
        (calibration.projectorMatrix * calibration.tableToProjector.rotation()).cast<float>();
    projectorTranslation_ =
        (calibration.projectorMatrix * calibration.tableToProjector.translation()).cast<float>();
    cameraToProjector_ = calibration.cameraToProjectorHomography(0.0);

    const Eigen::Vector2d centre = calibration.displayCentreOnTable();
    referenceDistance2_ = (projectorCentre_ - Eigen::Vector3d(centre.x(), centre.y(), 0)).squaredNorm();
    referenceCosine_ = projectorCentre_.z() / std::sqrt(referenceDistance2_);

    // Panel vignetting: quadratic in the distance from the panel centre, `projectorCornerFalloff` at corners.
    panelFalloff_.create(panelSize, CV_32FC3);
    const double halfW = (panelSize.width - 1) / 2.0, halfH = (panelSize.height - 1) / 2.0;
    for (int y = 0; y < panelSize.height; ++y)
        for (int x = 0; x < panelSize.width; ++x) {
            const double r2 =
                ((x - halfW) * (x - halfW) + (y - halfH) * (y - halfH)) / (halfW * halfW + halfH * halfH);
            panelFalloff_.at<cv::Vec3f>(y, x) =
                cv::Vec3f::all(static_cast<float>(1.0 - (1.0 - p.projectorCornerFalloff) * r2));
        }

    // The table seen by each camera pixel: albedo integrated over the pixel, and the projector's light
    // falloff.
    const Eigen::Matrix3d cameraToTable = calibration.tableToCameraHomography().inverse();
    double minX = 1e18, minY = 1e18, maxX = -1e18, maxY = -1e18;
    for (const Eigen::Vector2d& corner :
         {Eigen::Vector2d(0, 0), Eigen::Vector2d(cameraSize.width, 0), Eigen::Vector2d(0, cameraSize.height),
          Eigen::Vector2d(cameraSize.width, cameraSize.height)}) {
        const Eigen::Vector2d table = core::applyHomography(cameraToTable, corner);
        minX = std::min(minX, table.x()), maxX = std::max(maxX, table.x());
        minY = std::min(minY, table.y()), maxY = std::max(maxY, table.y());
    }
    const double margin = 10.0;
    const SurfaceTexture surface = makeSurface(
        p.surface,
        cv::Rect2d(minX - margin, minY - margin, maxX - minX + 2 * margin, maxY - minY + 2 * margin),
        kTexelMm, p.seed);
    const int n = p.pixelSamples;
    albedo_ = cv::Mat::zeros(cameraSize, CV_32FC3);
    cv::Mat sample;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            Eigen::Matrix3d offset = Eigen::Matrix3d::Identity();
            offset(0, 2) = (i + 0.5) / n - 0.5, offset(1, 2) = (j + 0.5) / n - 0.5;
            cv::warpPerspective(surface.albedo, sample, toCv(surface.tableToTexel * cameraToTable * offset),
                                cameraSize, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
            cv::accumulate(sample, albedo_);
        }
    albedo_ /= 255.0 * n * n;
    tableIncidence_.create(cameraSize, CV_32FC1);
    for (int y = 0; y < cameraSize.height; ++y)
        for (int x = 0; x < cameraSize.width; ++x) {
            const Eigen::Vector2d table = core::applyHomography(cameraToTable, {x, y});
            const double r2 = (projectorCentre_ - Eigen::Vector3d(table.x(), table.y(), 0)).squaredNorm();
            const double cosine = projectorCentre_.z() / std::sqrt(r2);
            tableIncidence_.at<float>(y, x) =
                static_cast<float>(referenceDistance2_ / r2 * cosine / referenceCosine_);
        }
    ambientBgr_ = toBgr(p.ambientColour.cast<float>());
    cv::Mat incidence3;
    cv::merge(std::vector<cv::Mat>{tableIncidence_, tableIncidence_, tableIncidence_}, incidence3);
    tableWeight_ = albedo_.mul(incidence3);
    buildScene(true);

    const Eigen::Vector3f skin = skinReflectance(p.skinTone);
    skinBgr_ = toBgr(skin);
    nailBgr_ = toBgr(Eigen::Vector3f(0.5f * skin + Eigen::Vector3f(0.30f, 0.24f, 0.24f)));

    shadowDepth_ = cv::Mat(panelSize, CV_32FC1, cv::Scalar(kNoHit));
    shadowMask_ = cv::Mat::zeros(panelSize, CV_32FC1);
    blockedOnTable_.create(cameraSize, CV_32FC1);
    depth_ = cv::Mat(cameraSize, CV_32FC1, cv::Scalar(kNoHit));
    hitIndex_ = cv::Mat(cameraSize, CV_16SC1, cv::Scalar(-1));
}

double Renderer::meterExposureMs(double ambientLux, const std::vector<Props>& props) const {
    const cv::Scalar albedo = cv::mean(albedo_);
    const Eigen::Vector3f& ambient = ambientBgr_;
    double dnPerMs = 0.0;
    // A colour pixel records one channel's light, a monochrome pixel the light of all three.
    const bool mono = parameters_.cameraColour == CameraColour::Mono;
    const auto meter = [&](const Eigen::Vector3f& reflectance, double projectorLux) {
        double recorded = 0.0;
        for (int c = 0; c < 3; ++c) {
            const double radiance = reflectance[c] * (projectorLux + ambientLux * ambient[c]);
            const double value = radiance * sensor_.dnPerLux(c, 1.0);
            recorded = mono ? recorded + value : std::max(recorded, value);
        }
        dnPerMs = std::max(dnPerMs, recorded);
    };
    meter(Eigen::Vector3f(static_cast<float>(albedo[0]), static_cast<float>(albedo[1]),
                          static_cast<float>(albedo[2])),
          parameters_.projectorWhiteLux);
    // A prop's face nearer to the projector, or facing it more squarely, is lit more than the table.
    const auto meterFace = [&](const Eigen::Vector3d& centre, const Eigen::Vector3d& normal,
                               const Eigen::Vector3f& reflectance) {
        const Eigen::Vector3d toProjector = projectorCentre_ - centre;
        const double r2 = toProjector.squaredNorm();
        const double cosine = std::max(0.0, normal.dot(toProjector) / std::sqrt(r2));
        meter(reflectance,
              parameters_.projectorWhiteLux * referenceDistance2_ / r2 * cosine / referenceCosine_);
    };
    for (const Props& scene : props) {
        if (scene.card)
            meterFace(scene.card->faceToTable * Eigen::Vector3d(kCardLengthMm / 2, kCardWidthMm / 2, 0),
                      scene.card->faceToTable.linear().col(2), kCardAlbedo);
        if (scene.board)
            meterFace(scene.board->faceToTable.translation(), scene.board->faceToTable.linear().col(2),
                      kBoardAlbedo);
    }
    if (dnPerMs <= 0.0)
        return parameters_.maxExposureMs;
    const double target = parameters_.autoExposureLevel * (255.0 - sensor_.blackLevelDn());
    return std::min(parameters_.maxExposureMs, target / dnPerMs);
}

void Renderer::setContent(const cv::Mat& displayContent) {
    CV_Assert(displayContent.type() == CV_8UC3 && displayContent.size() == calibration_.displaySize);
    cv::warpPerspective(displayContent, panelContent_, toCv(calibration_.displayToProjector),
                        calibration_.projectorSize, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                        cv::Scalar::all(0));
    if (projectorImage_.empty())
        showPanelImage(panelContent_);
}

void Renderer::setDisplay(cv::Size displaySize, const Eigen::Matrix3d& displayToProjector) {
    calibration_.displaySize = displaySize;
    calibration_.displayToProjector = displayToProjector;
    panelContent_.release();
}

void Renderer::setProjectorImage(const cv::Mat& projectorImage) {
    if (projectorImage.empty()) {
        if (projectorImage_.empty())
            return;
        projectorImage_.release();
        if (!panelContent_.empty()) {
            showPanelImage(panelContent_);
        } else {
            panelLight_[0].release(), panelLight_[1].release();  // no content yet: setContent must come
            projectedValid_[0] = projectedValid_[1] = false;
        }
        return;
    }
    if (projectorImage.size() != calibration_.projectorSize ||
        (projectorImage.type() != CV_8UC1 && projectorImage.type() != CV_8UC3))
        throw std::invalid_argument("projector image: expected an 8-bit gray or BGR image of " +
                                    std::to_string(calibration_.projectorSize.width) + "x" +
                                    std::to_string(calibration_.projectorSize.height) + " pixels, got " +
                                    std::to_string(projectorImage.cols) + "x" +
                                    std::to_string(projectorImage.rows) + " with " +
                                    std::to_string(projectorImage.channels()) + " channel(s) of type " +
                                    std::to_string(projectorImage.depth()));
    if (projectorImage.type() == CV_8UC1)
        cv::cvtColor(projectorImage, projectorImage_, cv::COLOR_GRAY2BGR);
    else
        projectorImage.copyTo(projectorImage_);
    showPanelImage(projectorImage_);
}

void Renderer::showPanelImage(const cv::Mat& panelImage) {
    const SimParameters& p = parameters_;
    const cv::Size cameraSize = calibration_.cameraSize;
    cv::Mat images[2];
    core::embedCode(panelImage, pattern_, p.delta, images[0], images[1]);

    // Projector transfer: digital level -> light, as a fraction of white.
    cv::Mat transfer(1, 256, CV_32F);
    for (int level = 0; level < 256; ++level)
        transfer.at<float>(level) = static_cast<float>(
            p.projectorWhiteLux * (p.projectorBlackLevel + (1.0 - p.projectorBlackLevel) *
                                                               std::pow(level / 255.0, p.projectorGamma)));

    // Blur scales in panel pixels: the camera pixel's footprint (a box, as a Gaussian of equal variance) and
    // the light's spread inside skin.
    const Eigen::Vector2d cameraCentre((cameraSize.width - 1) / 2.0, (cameraSize.height - 1) / 2.0);
    const double footprint = jacobianScale(cameraToProjector_, cameraCentre);
    const double mmPerPanelPixel = jacobianScale(calibration_.tableToProjectorHomography().inverse(),
                                                 core::applyHomography(cameraToProjector_, cameraCentre));
    const double direct2 = p.projectorDefocusPx * p.projectorDefocusPx + footprint * footprint / 12.0;

    cv::Mat& light = work_[0];
    for (int polarity = 0; polarity < 2; ++polarity) {
        cv::LUT(images[polarity], transfer, light);
        light = light.mul(panelFalloff_);
        blurIfNeeded(light, panelLight_[polarity], p.projectorDefocusPx);
        projectLight(polarity);

        // Skin: part of the light is reflected at the surface, the rest leaves after spreading under the skin
        // (red farthest). Both seen through the camera pixel's footprint.
        cv::Mat direct;
        blurIfNeeded(light, direct, std::sqrt(direct2));
        std::vector<cv::Mat> channels(3);
        cv::split(light, channels);
        const Eigen::Vector3d scatterBgr(p.skinScatterMm.z(), p.skinScatterMm.y(), p.skinScatterMm.x());
        for (int c = 0; c < 3; ++c) {
            const double spread = scatterBgr[c] / mmPerPanelPixel;
            blurIfNeeded(channels[c], channels[c], std::sqrt(direct2 + spread * spread));
        }
        cv::Mat scattered;
        cv::merge(channels, scattered);
        cv::addWeighted(direct, 1.0 - p.skinScatterFraction, scattered, p.skinScatterFraction, 0.0,
                        skinLight_[polarity]);
    }
}

void Renderer::projectLight(int polarityIndex) {
    const SimParameters& p = parameters_;
    const cv::Size cameraSize = calibration_.cameraSize;
    // Each plane: the projector's light through its homography, integrated over each camera pixel by n x n
    // samples, times what the plane reflects of it there.
    const int n = propsFine_ ? p.pixelSamples : 1;
    cv::Mat& shadowed = work_[1];
    cv::Mat& sample = work_[2];
    cv::Mat& accumulated = work_[3];
    cv::Mat& projected = projected_[polarityIndex];
    projected.create(cameraSize, CV_32FC3);
    projected.setTo(cv::Scalar::all(0));
    if (props_.board) {
        cv::Mat shadow3;
        cv::merge(std::vector<cv::Mat>{boardShadow_, boardShadow_, boardShadow_}, shadow3);
        shadowed = panelLight_[polarityIndex] - panelLight_[polarityIndex].mul(shadow3);
    }
    for (const ScenePlane& plane : planes_) {
        const cv::Rect& box = plane.cameraBox;
        if (box.area() == 0)
            continue;
        const cv::Mat& light = plane.shadowedByBoard ? shadowed : panelLight_[polarityIndex];
        accumulated.create(box.size(), CV_32FC3);
        accumulated.setTo(cv::Scalar::all(0));
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                Eigen::Matrix3d offset = Eigen::Matrix3d::Identity();
                offset(0, 2) = box.x + (i + 0.5) / n - 0.5, offset(1, 2) = box.y + (j + 0.5) / n - 0.5;
                cv::warpPerspective(light, sample, toCv(plane.cameraToProjector * offset), box.size(),
                                    cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT,
                                    cv::Scalar::all(0));
                accumulated += sample;
            }
        cv::Mat target = projected(box);
        cv::scaleAdd(accumulated.mul(plane.weight), 1.0 / (n * n), target, target);
    }
    blurIfNeeded(projected, projectedBlurred_[polarityIndex], p.cameraDefocusPx);
    projectedValid_[polarityIndex] = true;
    ++contentVersion_;
}

void Renderer::setProps(const Props& props, bool fine) {
    if (props == props_ && fine == propsFine_)
        return;
    props_ = props;
    buildScene(fine);
    if (panelLight_[0].empty())
        return;
    projectedValid_[0] = projectedValid_[1] = false;
    if (fine) {
        projectLight(0);
        projectLight(1);
    }
}

namespace {

// A rectangle of a prop's face, for ray casting.
struct FaceRect {
    Eigen::Vector3d origin, xAxis, yAxis, normal;  // table frame; axes are unit vectors
    double x0, x1, y0, y1;                         // extent along the axes, mm

    static FaceRect of(const Eigen::Isometry3d& faceToTable, double x0, double x1, double y0, double y1) {
        const Eigen::Matrix3d r = faceToTable.rotation();
        return {faceToTable.translation(), r.col(0), r.col(1), r.col(2), x0, x1, y0, y1};
    }
    // Ray parameter of the hit with the face's plane (may be outside the rectangle); infinity when parallel.
    double planeHit(const Eigen::Vector3d& from, const Eigen::Vector3d& direction) const {
        const double along = normal.dot(direction);
        return std::abs(along) < 1e-12 ? std::numeric_limits<double>::infinity()
                                       : normal.dot(origin - from) / along;
    }
    bool contains(const Eigen::Vector3d& point) const {
        const Eigen::Vector3d d = point - origin;
        const double x = xAxis.dot(d), y = yAxis.dot(d);
        return x >= x0 && x <= x1 && y >= y0 && y <= y1;
    }
};

// A plane's homography from its own 2-D frame (mm) to a device's pixels.
Eigen::Matrix3d planeToPixels(const Eigen::Matrix3d& intrinsics, const Eigen::Isometry3d& tableToDevice,
                              const Eigen::Isometry3d& faceToTable) {
    const Eigen::Isometry3d faceToDevice = tableToDevice * faceToTable;
    Eigen::Matrix3d m;
    m.col(0) = faceToDevice.rotation().col(0);
    m.col(1) = faceToDevice.rotation().col(1);
    m.col(2) = faceToDevice.translation();
    return intrinsics * m;
}

}  // namespace

void Renderer::buildScene(bool fine) {
    propsFine_ = fine;
    const cv::Size cameraSize = calibration_.cameraSize;
    const cv::Rect whole(0, 0, cameraSize.width, cameraSize.height);
    planes_.resize(1);
    ScenePlane& table = planes_[0];
    table.cameraToProjector = cameraToProjector_;
    table.cameraBox = whole;
    tableWeight_.copyTo(table.weight);
    table.shadowedByBoard = props_.board.has_value();
    albedo_.copyTo(sceneAlbedo_);
    sceneHeight_ = cv::Mat::zeros(cameraSize, CV_32FC1);
    planeLabel_ = cv::Mat::zeros(cameraSize, CV_8UC1);

    // The props' faces, nearest first where they lie on each other: a card on the board lies above it.
    struct Face {
        FaceRect rect;
        int plane;  // index into planes_
        Eigen::Vector3f albedo;
        std::optional<FaceRect> stripe;
    };
    std::vector<Face> faces;
    const auto addPlane = [&](const Eigen::Isometry3d& faceToTable,
                              const std::array<Eigen::Vector3d, 4>& corners) {
        ScenePlane plane;
        plane.cameraToProjector =
            planeToPixels(calibration_.projectorMatrix, calibration_.tableToProjector, faceToTable) *
            planeToPixels(calibration_.cameraMatrix, calibration_.tableToCamera, faceToTable).inverse();
        double minX = 1e18, minY = 1e18, maxX = -1e18, maxY = -1e18;
        for (const Eigen::Vector3d& corner : corners) {
            const Eigen::Vector3d q = calibration_.cameraMatrix * (calibration_.tableToCamera * corner);
            minX = std::min(minX, q.x() / q.z()), maxX = std::max(maxX, q.x() / q.z());
            minY = std::min(minY, q.y() / q.z()), maxY = std::max(maxY, q.y() / q.z());
        }
        plane.cameraBox =
            cv::Rect(static_cast<int>(std::floor(minX)) - 1, static_cast<int>(std::floor(minY)) - 1,
                     static_cast<int>(std::ceil(maxX - minX)) + 3,
                     static_cast<int>(std::ceil(maxY - minY)) + 3) &
            whole;
        plane.weight = cv::Mat::zeros(plane.cameraBox.size(), CV_32FC3);
        planes_.push_back(plane);
        return static_cast<int>(planes_.size()) - 1;
    };
    if (props_.card) {
        const Eigen::Isometry3d& pose = props_.card->faceToTable;
        const double x0 = (kCardLengthMm - kStripeLengthMm) / 2.0;
        faces.push_back({FaceRect::of(pose, 0, kCardLengthMm, 0, kCardWidthMm),
                         addPlane(pose, cardCorners(*props_.card)), kCardAlbedo,
                         FaceRect::of(pose, x0, x0 + kStripeLengthMm, kStripeOffsetMm,
                                      kStripeOffsetMm + kStripeWidthMm)});
    }
    if (props_.board) {
        const BoardProp& board = *props_.board;
        const double hx = board.sizeMm.width / 2.0, hy = board.sizeMm.height / 2.0;
        faces.push_back({FaceRect::of(board.faceToTable, -hx, hx, -hy, hy),
                         addPlane(board.faceToTable, boardCorners(board)), kBoardAlbedo, std::nullopt});
        // The board's outline as the projector sees it: the light it takes from what lies behind it.
        boardShadow_.create(calibration_.projectorSize, CV_8UC1);
        boardShadow_.setTo(0);
        constexpr int kShift = 8;
        std::vector<cv::Point> outline;
        for (const Eigen::Vector3d& corner : boardCorners(board)) {
            const Eigen::Vector3d q = calibration_.projectorMatrix * (calibration_.tableToProjector * corner);
            outline.emplace_back(static_cast<int>(std::lround(q.x() / q.z() * (1 << kShift))),
                                 static_cast<int>(std::lround(q.y() / q.z() * (1 << kShift))));
        }
        cv::fillConvexPoly(boardShadow_, outline, cv::Scalar(255), cv::LINE_AA, kShift);
        boardShadow_.convertTo(boardShadow_, CV_32F, 1.0 / 255.0);
        blurIfNeeded(boardShadow_, boardShadow_, parameters_.projectorDefocusPx);
        // A card not lying on the board is in its shadow where the board is nearer to the projector.
        if (props_.card) {
            const Eigen::Vector3d centre =
                props_.card->faceToTable * Eigen::Vector3d(kCardLengthMm / 2, kCardWidthMm / 2, 0);
            const double t = faces.back().rect.planeHit(projectorCentre_, centre - projectorCentre_);
            planes_[faces.front().plane].shadowedByBoard = t > 0.0 && t < 1.0;
        }
    }
    cv::Rect region;  // empty without props: the table as precomputed
    for (size_t k = 1; k < planes_.size(); ++k)
        region |= planes_[k].cameraBox;
    // Where each sample ray lands: the nearest face it hits inside its rectangle, else the table.
    struct Hit {
        int plane;
        int material;  // 0 table, 1 face, 2 stripe
        Eigen::Vector3f albedo;
        float incidence;
        float height;
    };
    const auto cast = [&](double x, double y, const cv::Vec3f& tableAlbedo) {
        const Eigen::Vector3d direction = cameraPixelToRay_ * Eigen::Vector3d(x, y, 1.0);
        double nearest = std::numeric_limits<double>::infinity();
        const Face* seen = nullptr;
        for (const Face& face : faces) {
            const double t = face.rect.planeHit(cameraCentre_, direction);
            if (t > 0.0 && t < nearest && face.rect.contains(cameraCentre_ + t * direction))
                nearest = t, seen = &face;
        }
        Hit hit;
        Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
        if (seen) {
            const Eigen::Vector3d point = cameraCentre_ + nearest * direction;
            hit.plane = seen->plane;
            const bool stripe = seen->stripe && seen->stripe->contains(point);
            hit.material = stripe ? 2 : 1;
            hit.albedo = stripe ? kStripeAlbedo : seen->albedo;
            normal = seen->rect.normal;
            hit.height = static_cast<float>(point.z());
        } else {
            nearest = -cameraCentre_.z() / direction.z();
            hit.plane = 0;
            hit.material = 0;
            hit.albedo = Eigen::Vector3f(tableAlbedo[0], tableAlbedo[1], tableAlbedo[2]);
            hit.height = 0.0f;
        }
        const Eigen::Vector3d point = cameraCentre_ + nearest * direction;
        const Eigen::Vector3d toProjector = projectorCentre_ - point;
        const double r2 = toProjector.squaredNorm();
        const double cosine = std::max(0.0, normal.dot(toProjector) / std::sqrt(r2));
        hit.incidence = static_cast<float>(referenceDistance2_ / r2 * cosine / referenceCosine_);
        return hit;
    };
    const int coarse = fine ? parameters_.pixelSamples : 1;
    constexpr int kEdgeSamples = 8;  // per side, where a pixel sees several surfaces or materials
    std::vector<Hit> hits;
    for (int y = region.y; y < region.y + region.height; ++y)
        for (int x = region.x; x < region.x + region.width; ++x) {
            const cv::Vec3f tableAlbedo = albedo_.at<cv::Vec3f>(y, x);
            const auto sampleGrid = [&](int n) {
                hits.clear();
                for (int j = 0; j < n; ++j)
                    for (int i = 0; i < n; ++i)
                        hits.push_back(cast(x + (i + 0.5) / n - 0.5, y + (j + 0.5) / n - 0.5, tableAlbedo));
            };
            sampleGrid(coarse);
            const auto differs = [&](const Hit& h) {
                return h.plane != hits.front().plane || h.material != hits.front().material;
            };
            if (fine && std::any_of(hits.begin(), hits.end(), differs))
                sampleGrid(kEdgeSamples);
            if (hits.front().plane == 0 && !std::any_of(hits.begin(), hits.end(), differs))
                continue;  // the bare table, as precomputed
            std::array<float, 8> coverage{};
            Eigen::Vector3f albedo = Eigen::Vector3f::Zero();
            const float share = 1.0f / static_cast<float>(hits.size());
            cv::Vec3f& tableWeight = planes_[0].weight.at<cv::Vec3f>(y, x);
            tableWeight = cv::Vec3f::all(0.0f);
            for (const Hit& h : hits) {
                const Eigen::Vector3f w = h.albedo * (h.incidence * share);
                ScenePlane& plane = planes_[h.plane];
                cv::Vec3f& weight = plane.weight.at<cv::Vec3f>(y - plane.cameraBox.y, x - plane.cameraBox.x);
                weight += cv::Vec3f(w.x(), w.y(), w.z());
                albedo += h.albedo * share;
                coverage[h.plane] += share;
            }
            sceneAlbedo_.at<cv::Vec3f>(y, x) = cv::Vec3f(albedo.x(), albedo.y(), albedo.z());
            planeLabel_.at<uchar>(y, x) =
                static_cast<uchar>(std::max_element(coverage.begin(), coverage.end()) - coverage.begin());
            // The truth's height: the central ray (the only sample of a coarse cast).
            sceneHeight_.at<float>(y, x) =
                hits.size() == 1 ? hits.front().height : cast(x, y, tableAlbedo).height;
        }
    ambientTerm_ = sceneAlbedo_.mul(cv::Scalar(ambientBgr_.x(), ambientBgr_.y(), ambientBgr_.z()));
    blurIfNeeded(ambientTerm_, ambientBlurred_, parameters_.cameraDefocusPx);
    ++contentVersion_;
}

void Renderer::castShadows(const std::vector<PreparedCapsule>& capsules, const cv::Rect& box) {
    if (shadowBox_.area() > 0) {
        shadowDepth_(shadowBox_).setTo(kNoHit);
        shadowMask_(shadowBox_).setTo(0.0f);
    }
    shadowBox_ = cv::Rect();
    if (box.area() == 0)
        return;
    for (const PreparedCapsule& capsule : capsules) {
        const cv::Rect& b = capsule.projectorBox;
        const Eigen::Vector3f step = capsule.projectorPixelToLocal.col(0);
        for (int v = b.y; v < b.y + b.height; ++v) {
            float* depth = shadowDepth_.ptr<float>(v);
            Eigen::Vector3f local = capsule.projectorPixelToLocal * Eigen::Vector3f(b.x, v, 1.0f);
            bool inside = false;
            for (int u = b.x; u < b.x + b.width; ++u, local += step) {
                const float t = capsule.projector.intersectLocal(local);
                if (t > 0.0f) {
                    inside = true;
                    depth[u] = std::min(depth[u], t);
                } else if (inside) {
                    break;  // a capsule's silhouette is convex: each row crosses it once
                }
            }
        }
    }
    // The shadow's edge is as soft as the projector's blur.
    const int reach = static_cast<int>(std::ceil(3.0 * parameters_.projectorDefocusPx)) + 1;
    shadowBox_ = cv::Rect(box.x - reach, box.y - reach, box.width + 2 * reach, box.height + 2 * reach) &
                 cv::Rect(0, 0, shadowDepth_.cols, shadowDepth_.rows);
    for (int v = box.y; v < box.y + box.height; ++v) {
        const float* depth = shadowDepth_.ptr<float>(v);
        float* mask = shadowMask_.ptr<float>(v);
        for (int u = box.x; u < box.x + box.width; ++u)
            mask[u] = depth[u] < kNoHit ? 1.0f : 0.0f;
    }
    if (parameters_.projectorDefocusPx > 0.05) {
        cv::Mat region = shadowMask_(shadowBox_);
        cv::GaussianBlur(region, region, {0, 0}, parameters_.projectorDefocusPx);
    }
}

cv::Rect Renderer::shadowOnTable(const cv::Rect& projectorBox) const {
    if (projectorBox.area() == 0)
        return {};
    cv::Rect onPlanes;
    for (const ScenePlane& plane : planes_) {
        const Eigen::Matrix3d projectorToCamera = plane.cameraToProjector.inverse();
        double minX = 1e18, minY = 1e18, maxX = -1e18, maxY = -1e18;
        for (int corner = 0; corner < 4; ++corner) {
            const Eigen::Vector2d panel(projectorBox.x + ((corner & 1) ? projectorBox.width : 0),
                                        projectorBox.y + ((corner & 2) ? projectorBox.height : 0));
            const Eigen::Vector2d camera = core::applyHomography(projectorToCamera, panel);
            minX = std::min(minX, camera.x()), maxX = std::max(maxX, camera.x());
            minY = std::min(minY, camera.y()), maxY = std::max(maxY, camera.y());
        }
        const cv::Rect box(static_cast<int>(minX) - 2, static_cast<int>(minY) - 2,
                           static_cast<int>(maxX - minX) + 5, static_cast<int>(maxY - minY) + 5);
        onPlanes |= box & plane.cameraBox;
    }
    return onPlanes;
}

void Renderer::shadeTable(const cv::Rect& box, const cv::Mat& projected) {
    if (box.area() == 0 || shadowBox_.area() == 0)
        return;
    // The shadow mask seen through each plane: camera pixel (x, y) of `box` -> panel pixel of shadowBox_;
    // each pixel takes it through the plane it mostly sees.
    Eigen::Matrix3d toPanel = Eigen::Matrix3d::Identity(), fromCamera = Eigen::Matrix3d::Identity();
    toPanel(0, 2) = -shadowBox_.x, toPanel(1, 2) = -shadowBox_.y;
    fromCamera(0, 2) = box.x, fromCamera(1, 2) = box.y;
    cv::Mat blocked = blockedOnTable_(box);
    cv::warpPerspective(shadowMask_(shadowBox_), blocked,
                        toCv(toPanel * planes_[0].cameraToProjector * fromCamera), box.size(),
                        cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT, cv::Scalar(0));
    for (size_t k = 1; k < planes_.size(); ++k) {
        const cv::Rect part = box & planes_[k].cameraBox;
        if (part.area() == 0)
            continue;
        Eigen::Matrix3d fromPart = Eigen::Matrix3d::Identity();
        fromPart(0, 2) = part.x, fromPart(1, 2) = part.y;
        cv::Mat onPlane;
        cv::warpPerspective(shadowMask_(shadowBox_), onPlane,
                            toCv(toPanel * planes_[k].cameraToProjector * fromPart), part.size(),
                            cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT, cv::Scalar(0));
        onPlane.copyTo(blockedOnTable_(part), planeLabel_(part) == static_cast<int>(k));
    }
    for (int y = 0; y < box.height; ++y) {
        const float* fraction = blocked.ptr<float>(y);
        float* out = radiance_.ptr<float>(box.y + y) + 3 * box.x;
        const float* lit = projected.ptr<float>(box.y + y) + 3 * box.x;
        for (int x = 0; x < box.width; ++x)
            for (int c = 0; c < 3; ++c)
                out[3 * x + c] -= fraction[x] * lit[3 * x + c];
    }
}

void Renderer::shadeHit(const PreparedCapsule& capsule, const Eigen::Vector3f& direction, float t,
                        int polarityIndex, double ambientLux, float* bgr, float& height) const {
    const Eigen::Vector3f point = cameraCentre_.cast<float>() + t * direction;
    const Eigen::Vector3f normal = capsule.camera.normal(direction, t);
    height = point.z();
    // Albedo: nail on the back of the last bone's outer part, skin elsewhere.
    Eigen::Vector3f albedo = skinBgr_;
    if (capsule.part == HandPart::Fingertip && capsule.camera.dorsal(direction, t) > 0.45f &&
        capsule.camera.axial(direction, t) > 0.35f * capsule.length)
        albedo = nailBgr_;
    // Light from the projector pixel that sees the point, unless a hand part is nearer to the projector.
    Eigen::Vector3f irradiance = Eigen::Vector3f::Zero();
    const Eigen::Vector3f q = projectorProjection_ * point + projectorTranslation_;
    const Eigen::Vector3f toProjector = projectorCentre_.cast<float>() - point;
    const float distance2 = toProjector.squaredNorm();
    const float cosine = normal.dot(toProjector) / std::sqrt(distance2);
    if (q.z() > 0.0f && cosine > 0.0f) {
        const float u = q.x() / q.z(), v = q.y() / q.z();
        const bool inside =
            u > -0.5f && v > -0.5f && u < shadowDepth_.cols - 0.5f && v < shadowDepth_.rows - 0.5f;
        const int iu = static_cast<int>(u + 0.5f), iv = static_cast<int>(v + 0.5f);
        float light[3];
        if (inside && shadowDepth_.at<float>(iv, iu) >= q.z() - kShadowBiasMm &&
            sampleBilinear<3>(skinLight_[polarityIndex], u, v, light)) {
            const float geometry =
                static_cast<float>(referenceDistance2_ / referenceCosine_) * cosine / distance2;
            irradiance = Eigen::Vector3f(light[0], light[1], light[2]) * geometry;
        }
    }
    // Room light from above: the upper hemisphere is brighter than the table's reflection below.
    irradiance += ambientBgr_ * static_cast<float>(ambientLux) * (0.6f + 0.4f * normal.z());
    const Eigen::Vector3f radiance = albedo.cwiseProduct(irradiance);
    bgr[0] = radiance.x(), bgr[1] = radiance.y(), bgr[2] = radiance.z();
}

void Renderer::castHands(const std::vector<PreparedCapsule>& capsules, const cv::Rect& box, int polarityIndex,
                         double ambientLux, FrameTruth* truth) {
    if (box.area() == 0)
        return;
    depth_(box).setTo(kNoHit);
    hitIndex_(box).setTo(-1);
    for (size_t k = 0; k < capsules.size(); ++k) {
        const PreparedCapsule& capsule = capsules[k];
        const cv::Rect& b = capsule.cameraBox;
        const Eigen::Vector3f step = capsule.cameraPixelToLocal.col(0);
        for (int y = b.y; y < b.y + b.height; ++y) {
            float* depth = depth_.ptr<float>(y);
            short* index = hitIndex_.ptr<short>(y);
            Eigen::Vector3f local = capsule.cameraPixelToLocal * Eigen::Vector3f(b.x, y, 1.0f);
            bool inside = false;
            for (int x = b.x; x < b.x + b.width; ++x, local += step) {
                const float t = capsule.camera.intersectLocal(local);
                if (t > 0.0f) {
                    inside = true;
                    if (t < depth[x]) {
                        depth[x] = t;
                        index[x] = static_cast<short>(k);
                    }
                } else if (inside) {
                    break;  // a capsule's silhouette is convex: each row crosses it once
                }
            }
        }
    }
    const Eigen::Matrix3f pixelToRay = cameraPixelToRay_.cast<float>();
    const int w = box.width, h = box.height;
    for (int y = box.y; y < box.y + h; ++y) {
        const short* index = hitIndex_.ptr<short>(y);
        const short* above = hitIndex_.ptr<short>(std::max(y - 1, box.y));
        const short* below = hitIndex_.ptr<short>(std::min(y + 1, box.y + h - 1));
        float* out = radiance_.ptr<float>(y);
        for (int x = box.x; x < box.x + w; ++x) {
            const bool hit = index[x] >= 0;
            const int left = std::max(x - 1, box.x), right = std::min(x + 1, box.x + w - 1);
            const bool edge = (index[left] >= 0) != hit || (index[right] >= 0) != hit ||
                              (above[x] >= 0) != hit || (below[x] >= 0) != hit;
            if (!hit && !edge)
                continue;
            int shadeIndex = index[x];
            float shadeT = depth_.at<float>(y, x);
            Eigen::Vector3f shadeDirection = pixelToRay * Eigen::Vector3f(x, y, 1.0f);
            float coverage = hit ? 1.0f : 0.0f;
            if (edge) {
                // Integrate the silhouette over the pixel with four samples, against the capsules seen by the
                // pixel and its neighbours.
                short candidates[5] = {index[x], index[left], index[right], above[x], below[x]};
                int hits = 0;
                for (int s = 0; s < 4; ++s) {
                    const Eigen::Vector3f pixel(x + ((s & 1) ? 0.25f : -0.25f),
                                                y + ((s & 2) ? 0.25f : -0.25f), 1.0f);
                    float best = kNoHit;
                    int bestIndex = -1;
                    for (int c = 0; c < 5; ++c) {
                        const short k = candidates[c];
                        if (k < 0 || (c > 0 && std::find(candidates, candidates + c, k) != candidates + c))
                            continue;
                        const float t =
                            capsules[k].camera.intersectLocal(capsules[k].cameraPixelToLocal * pixel);
                        if (t > 0.0f && t < best)
                            best = t, bestIndex = k;
                    }
                    if (bestIndex < 0)
                        continue;
                    ++hits;
                    if (shadeIndex < 0)
                        shadeIndex = bestIndex, shadeT = best, shadeDirection = pixelToRay * pixel;
                }
                coverage = hits / 4.0f;
            }
            if (shadeIndex < 0 || coverage <= 0.0f)
                continue;
            float colour[3];
            float height = 0.0f;
            shadeHit(capsules[shadeIndex], shadeDirection, shadeT, polarityIndex, ambientLux, colour, height);
            for (int c = 0; c < 3; ++c)
                out[3 * x + c] = coverage * colour[c] + (1.0f - coverage) * out[3 * x + c];
            if (hit && truth) {
                truth->handMask.at<uchar>(y, x) = 255;
                truth->visibleHeightMm.at<float>(y, x) = height;
            }
        }
    }
}

void Renderer::prepare(const std::vector<HandPose>& hands, std::vector<PreparedCapsule>& capsules,
                       cv::Rect& cameraBox, cv::Rect& projectorBox) const {
    const cv::Size cameraSize = calibration_.cameraSize, panelSize = calibration_.projectorSize;
    const Eigen::Matrix3f cameraPixelToRay = cameraPixelToRay_.cast<float>();
    const Eigen::Matrix3f projectorPixelToRay = projectorPixelToRay_.cast<float>();
    capsules.clear();
    cameraBox = projectorBox = cv::Rect();
    for (const HandPose& hand : hands)
        for (const HandCapsule& part : buildHand(hand).capsules) {
            PreparedCapsule capsule{
                CapsuleHit(part.shape, cameraCentre_),
                CapsuleHit(part.shape, projectorCentre_),
                Eigen::Matrix3f(),
                Eigen::Matrix3f(),
                capsuleBox(part.shape, calibration_.cameraMatrix, calibration_.tableToCamera, cameraSize),
                capsuleBox(part.shape, calibration_.projectorMatrix, calibration_.tableToProjector,
                           panelSize),
                part.part,
                static_cast<float>(part.shape.length)};
            capsule.cameraPixelToLocal = capsule.camera.toLocal() * cameraPixelToRay;
            capsule.projectorPixelToLocal = capsule.projector.toLocal() * projectorPixelToRay;
            cameraBox |= capsule.cameraBox;
            projectorBox |= capsule.projectorBox;
            capsules.push_back(std::move(capsule));
        }
}

void Renderer::render(const std::vector<std::vector<HandPose>>& exposure, core::Polarity polarity,
                      double ambientLux, double exposureMs, std::uint64_t noiseSeed, cv::Mat& image,
                      FrameTruth& truth) {
    CV_Assert(!panelLight_[0].empty() && exposure.size() % 2 == 1);
    const int polarityIndex = polarity == core::Polarity::Positive ? 0 : 1;
    if (!projectedValid_[polarityIndex])
        projectLight(polarityIndex);
    const cv::Size cameraSize = calibration_.cameraSize;
    const cv::Rect whole(0, 0, cameraSize.width, cameraSize.height);
    truth.handMask.create(cameraSize, CV_8UC1);
    truth.handMask.setTo(0);
    sceneHeight_.copyTo(truth.visibleHeightMm);
    truth.props = props_;
    truth.fingertips.clear();
    truth.ambientLux = ambientLux;
    truth.exposureMs = exposureMs;

    // The ground truth is the scene at mid-exposure, the middle instant.
    const size_t middle = exposure.size() / 2;
    const Eigen::Matrix3d displayFromTable = calibration_.displayToTableHomography().inverse();
    const Eigen::Matrix3d tableToCamera = calibration_.tableToCameraHomography();
    for (size_t h = 0; h < exposure[middle].size(); ++h) {
        const HandPose& hand = exposure[middle][h];
        const HandModel model = buildHand(hand);
        for (int f = 0; f < kFingerCount; ++f) {
            FingertipTruth tip;
            tip.hand = static_cast<int>(h);
            tip.finger = static_cast<Finger>(f);
            tip.id = static_cast<std::uint32_t>(h * kFingerCount + f);
            tip.pad = model.pads[f];
            tip.heightMm = tip.pad.z() < kContactToleranceMm ? 0.0 : tip.pad.z();
            tip.touching = tip.heightMm == 0.0;
            tip.presented = hand.presented[f];
            const Eigen::Vector2d display = core::applyHomography(displayFromTable, tip.pad.head<2>());
            const Eigen::Vector2d camera = core::applyHomography(tableToCamera, tip.pad.head<2>());
            tip.display = {display.x(), display.y()};
            tip.camera = {camera.x(), camera.y()};
            truth.fingertips.push_back(tip);
        }
    }

    // Hands at every instant, and the camera region they and their shadows change.
    const int instants = static_cast<int>(exposure.size());
    if (instantCapsules_.size() < exposure.size()) {
        instantCapsules_.resize(exposure.size());
        instantCameraBoxes_.resize(exposure.size());
        instantProjectorBoxes_.resize(exposure.size());
    }
    const int shadowReach = static_cast<int>(std::ceil(3.0 * parameters_.projectorDefocusPx)) + 1;
    cv::Rect changed;
    for (int i = 0; i < instants; ++i) {
        prepare(exposure[i], instantCapsules_[i], instantCameraBoxes_[i], instantProjectorBoxes_[i]);
        const cv::Rect& p = instantProjectorBoxes_[i];
        if (p.area() > 0)
            changed |= instantCameraBoxes_[i] |
                       shadowOnTable(cv::Rect(p.x - shadowReach, p.y - shadowReach, p.width + 2 * shadowReach,
                                              p.height + 2 * shadowReach) &
                                     cv::Rect(0, 0, shadowDepth_.cols, shadowDepth_.rows));
    }

    // The table as precomputed, camera blur included, kept per polarity: only what the hands changed in the
    // last frame of this polarity is restored. Then, where hands and their shadows change the table, the same
    // is computed again from the unblurred table with them, averaged over the instants of the exposure
    // (motion blur), and blurred.
    cv::Mat& frame = frameRadiance_[polarityIndex];
    cv::Rect& dirty = dirty_[polarityIndex];
    if (frame.empty() || frameAmbientLux_[polarityIndex] != ambientLux ||
        frameContentVersion_[polarityIndex] != contentVersion_) {
        cv::scaleAdd(ambientBlurred_, ambientLux, projectedBlurred_[polarityIndex], frame);
        frameAmbientLux_[polarityIndex] = ambientLux;
        frameContentVersion_[polarityIndex] = contentVersion_;
    } else if (dirty.area() > 0) {
        cv::scaleAdd(ambientBlurred_(dirty), ambientLux, projectedBlurred_[polarityIndex](dirty),
                     frame(dirty));
    }
    dirty = cv::Rect();
    if (changed.area() == 0) {
        castShadows({}, cv::Rect());  // clears the last frame's shadow map
    } else {
        const int reach = static_cast<int>(std::ceil(3.0 * parameters_.cameraDefocusPx));
        const cv::Rect blurredPart = cv::Rect(changed.x - reach, changed.y - reach, changed.width + 2 * reach,
                                              changed.height + 2 * reach) &
                                     whole;
        const cv::Rect inputPart = cv::Rect(changed.x - 2 * reach, changed.y - 2 * reach,
                                            changed.width + 4 * reach, changed.height + 4 * reach) &
                                   whole;
        if (radiance_.empty()) {
            radiance_ = cv::Mat::zeros(cameraSize, CV_32FC3);
            partBlurred_.create(cameraSize, CV_32FC3);
            exposed_.create(cameraSize, CV_32FC3);
        }
        for (int i = 0; i < instants; ++i) {
            cv::scaleAdd(ambientTerm_(inputPart), ambientLux, projected_[polarityIndex](inputPart),
                         radiance_(inputPart));
            castShadows(instantCapsules_[i], instantProjectorBoxes_[i]);
            shadeTable(shadowOnTable(shadowBox_), projected_[polarityIndex]);
            castHands(instantCapsules_[i], instantCameraBoxes_[i], polarityIndex, ambientLux,
                      i == static_cast<int>(middle) ? &truth : nullptr);
            if (instants == 1)
                break;
            if (i == 0)
                radiance_(inputPart).copyTo(exposed_(inputPart));
            else
                exposed_(inputPart) += radiance_(inputPart);
        }
        if (instants > 1)
            exposed_(inputPart).convertTo(radiance_(inputPart), CV_32F, 1.0 / instants);
        cv::Mat blurred = partBlurred_(inputPart);
        blurIfNeeded(radiance_(inputPart), blurred, parameters_.cameraDefocusPx);
        partBlurred_(blurredPart).copyTo(frame(blurredPart));
        dirty = blurredPart;
    }
    sensor_.expose(frame, exposureMs, noiseSeed, image);
}

}  // namespace everytouch::sim
