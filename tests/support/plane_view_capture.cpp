#include "support/plane_view_capture.h"

#include "core/table_rectangle.h"

namespace everytouch::test {

core::Result<core::PlaneView> captureView(const core::Calibration& surfaceRig,
                                          const std::optional<DarkRectangle>& rectangle, double noiseSigmaDn,
                                          unsigned seed, const core::CameraModel& knownCamera,
                                          const core::ChessboardOptions& chessboard) {
    SurfaceScene scene;
    scene.rig = surfaceRig;
    cv::Mat board;
    core::renderProjectorChessboard(chessboard, surfaceRig.projectorSize, board);
    const core::Result<core::ChessboardDetection> corners = core::detectProjectedChessboard(
        renderSurface(scene, board, noiseSigmaDn, seed), chessboard, surfaceRig.projectorSize);
    if (!corners.ok())
        return corners.failure();
    core::PlaneView view;
    view.cameraPoints = corners->cameraCorners;
    view.projectorPoints = corners->projectorCorners;
    if (!rectangle)
        return view;

    scene.rectangles.push_back(*rectangle);
    const cv::Mat white(surfaceRig.projectorSize, CV_8UC1, cv::Scalar(255));
    core::TableRectangleOptions options;
    options.sizeMm = rectangle->sizeMm;
    const core::Result<core::TableRectangleDetection> found =
        core::findTableRectangle(renderSurface(scene, white, noiseSigmaDn, seed + 1), options, knownCamera);
    if (!found.ok())
        return found.failure();
    std::array<Eigen::Vector2d, 4> raw;
    for (int corner = 0; corner < 4; ++corner)
        raw[corner] = knownCamera.distortPixel(found->corners[corner]);
    view.rectangleCorners = raw;
    return view;
}

}  // namespace everytouch::test
