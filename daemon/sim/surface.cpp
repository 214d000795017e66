#include "sim/surface.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

namespace everytouch::sim {

namespace {

cv::Mat smoothField(cv::Size size, double cellTexels, cv::RNG& rng) {
    const cv::Size coarse(std::max(2, static_cast<int>(size.width / cellTexels)),
                          std::max(2, static_cast<int>(size.height / cellTexels)));
    cv::Mat field(coarse, CV_32F);
    rng.fill(field, cv::RNG::NORMAL, 0.0, 1.0);
    cv::Mat large;
    cv::resize(field, large, size, 0, 0, cv::INTER_CUBIC);
    return large;
}

// Reflectance in 0..1 for BGR, with a smooth unevenness of `unevenness` (relative) and a fine grain.
cv::Mat unevenSurface(cv::Size size, const cv::Vec3f& reflectanceBgr, double unevenness, double mmPerTexel,
                      cv::RNG& rng) {
    const cv::Mat broad = smoothField(size, 60.0 / mmPerTexel, rng);
    cv::Mat grain(size, CV_32F);
    rng.fill(grain, cv::RNG::NORMAL, 0.0, 1.0);
    cv::GaussianBlur(grain, grain, {0, 0}, 0.6 / mmPerTexel);
    cv::Mat surface(size, CV_32FC3);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            const float factor =
                1.0f + static_cast<float>(unevenness) * broad.at<float>(y, x) + 0.02f * grain.at<float>(y, x);
            surface.at<cv::Vec3f>(y, x) = reflectanceBgr * factor;
        }
    return surface;
}

void addArtifacts(cv::Mat& surface, double mmPerTexel, cv::RNG& rng) {
    const cv::Size size = surface.size();
    const auto texels = [&](double mm) {
        return std::max(1, static_cast<int>(std::lround(mm / mmPerTexel)));
    };
    const auto anywhere = [&] { return cv::Point(rng.uniform(0, size.width), rng.uniform(0, size.height)); };
    // Drawing is done in reflectance (0..1) on a float image.
    for (int i = 0; i < 6; ++i) {  // sticky notes and printed sheets
        const cv::Point corner = anywhere();
        const cv::Size extent(texels(rng.uniform(50.0, 90.0)), texels(rng.uniform(50.0, 90.0)));
        const bool note = rng.uniform(0, 2) == 0;
        const cv::Scalar colour = note ? cv::Scalar(0.25, 0.75, 0.85) : cv::Scalar(0.82, 0.82, 0.80);
        cv::rectangle(surface, cv::Rect(corner, extent), colour, cv::FILLED);
        for (int line = 1; line < extent.height / texels(6.0); ++line)
            for (int word = 0; word < 6; ++word) {
                const int x0 = corner.x + texels(4.0) + word * extent.width / 6;
                cv::line(surface, {x0, corner.y + line * texels(6.0)},
                         {x0 + extent.width / 8, corner.y + line * texels(6.0)}, cv::Scalar(0.12, 0.12, 0.15),
                         texels(1.2));
            }
    }
    for (int i = 0; i < 5; ++i)  // coffee rings
        cv::circle(surface, anywhere(), texels(rng.uniform(30.0, 45.0)), cv::Scalar(0.30, 0.40, 0.55),
                   texels(rng.uniform(1.0, 3.0)), cv::LINE_AA);
    for (int i = 0; i < 8; ++i) {  // stains
        cv::Mat stain(size, CV_8UC1, cv::Scalar(0));
        cv::ellipse(stain, anywhere(),
                    cv::Size(texels(rng.uniform(10.0, 40.0)), texels(rng.uniform(8.0, 30.0))),
                    rng.uniform(0.0, 180.0), 0, 360, cv::Scalar(255), cv::FILLED);
        cv::Mat darkened;
        cv::multiply(surface, cv::Scalar(0.75, 0.8, 0.85), darkened);
        darkened.copyTo(surface, stain);
    }
    for (int i = 0; i < 12; ++i) {  // ink scribbles
        std::vector<cv::Point> stroke{anywhere()};
        for (int s = 0; s < 12; ++s)
            stroke.push_back(stroke.back() +
                             cv::Point(texels(rng.uniform(-12.0, 12.0)), texels(rng.uniform(-12.0, 12.0))));
        cv::polylines(surface, stroke, false, cv::Scalar(0.45, 0.15, 0.10), texels(0.8), cv::LINE_AA);
    }
    for (int i = 0; i < 30; ++i) {  // scratches, lighter or darker than the surface
        const cv::Point start = anywhere();
        const double angle = rng.uniform(0.0, M_PI), length = rng.uniform(20.0, 120.0);
        const cv::Point end =
            start + cv::Point(texels(length * std::cos(angle)), texels(length * std::sin(angle)));
        const double shade = rng.uniform(0, 2) ? 0.9 : 0.45;
        cv::line(surface, start, end, cv::Scalar::all(shade), 1, cv::LINE_AA);
    }
}

}  // namespace

SurfaceTexture makeSurface(SurfaceKind kind, const cv::Rect2d& areaMm, double mmPerTexel,
                           std::uint64_t seed) {
    cv::RNG rng(seed * 2654435761u + static_cast<std::uint64_t>(kind) + 17);
    const cv::Size size(static_cast<int>(std::ceil(areaMm.width / mmPerTexel)) + 1,
                        static_cast<int>(std::ceil(areaMm.height / mmPerTexel)) + 1);
    cv::Mat surface;
    switch (kind) {
        case SurfaceKind::Gray:
            surface = unevenSurface(size, {0.55f, 0.55f, 0.55f}, 0.015, mmPerTexel, rng);
            break;
        case SurfaceKind::Yellow:
            surface = unevenSurface(size, {0.16f, 0.55f, 0.70f}, 0.015, mmPerTexel, rng);
            break;
        case SurfaceKind::Artifacts:
            surface = unevenSurface(size, {0.52f, 0.60f, 0.66f}, 0.03, mmPerTexel, rng);
            addArtifacts(surface, mmPerTexel, rng);
            break;
    }
    SurfaceTexture texture;
    surface.convertTo(texture.albedo, CV_8UC3, 255.0);
    texture.tableToTexel << 1.0 / mmPerTexel, 0, -areaMm.x / mmPerTexel, 0, 1.0 / mmPerTexel,
        -areaMm.y / mmPerTexel, 0, 0, 1;
    return texture;
}

}  // namespace everytouch::sim
