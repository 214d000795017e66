#include "service/snapshot.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/code_image.h"
#include "service/snapshot_overlay.h"

namespace everytouch::service {

std::optional<SnapshotKind> parseSnapshotKind(std::string_view name) {
    if (name == "camera")
        return SnapshotKind::Camera;
    if (name == "texture")
        return SnapshotKind::Texture;
    if (name == "subtraction")
        return SnapshotKind::Subtraction;
    if (name == "mask")
        return SnapshotKind::Mask;
    if (name == "overlay")
        return SnapshotKind::Overlay;
    return std::nullopt;
}

void renderSnapshot(SnapshotKind kind, const core::FramePair& pair, const core::PipelineResult* detection,
                    const std::optional<core::Calibration>& calibration, cv::Mat& image) {
    if (kind == SnapshotKind::Camera) {
        pair.latest().image.copyTo(image);
        return;
    }
    cv::Mat subtraction, texture;
    if (detection) {
        subtraction = detection->subtraction;
        texture = detection->texture;
    } else {
        core::computeSubtractionAndTexture(pair, subtraction, texture);
    }
    switch (kind) {
        case SnapshotKind::Texture:
            image = texture;
            return;
        case SnapshotKind::Subtraction:
            subtraction.convertTo(image, CV_8U);  // saturates: negative differences become 0
            return;
        case SnapshotKind::Mask:
            if (detection && !detection->handMask.empty())
                image = detection->handMask;
            else
                image = cv::Mat::zeros(texture.size(), CV_8UC1);
            return;
        case SnapshotKind::Overlay:
            if (texture.channels() == 1)
                cv::cvtColor(texture, image, cv::COLOR_GRAY2BGR);
            else
                image = texture.clone();
            if (detection)
                drawDetection(*detection, image);
            drawOverlay(calibration, detection ? detection->contacts : core::Contacts{}, image);
            return;
        case SnapshotKind::Camera:
            return;
    }
}

std::vector<unsigned char> encodePng(const cv::Mat& image) {
    std::vector<unsigned char> bytes;
    cv::imencode(".png", image, bytes);
    return bytes;
}

}  // namespace everytouch::service
