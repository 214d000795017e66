#pragma once

#include <optional>
#include <vector>

#include "core/calibration.h"
#include "core/frame.h"
#include "core/plane_view.h"
#include "core/projector_camera_pair.h"
#include "core/projector_chessboard.h"
#include "core/result.h"
#include "core/table_rectangle.h"
#include "service/calibration_job.h"

namespace everytouch::service {

// The board the projector shows for the table set-up: smaller squares than the core's default, so that a
// white border of a few centimetres stays around it on the table for the card (paper Section IV: one
// projected chessboard and a card's stripe give the table).
core::ChessboardOptions tableSetUpChessboard();

// The card as the rectangle detector looks for it.
core::TableRectangleOptions cardRectangle(const CalibrationOptions& options);

// Whether the detectors can work with what a Calibrate call asked for: the board must fit a panel of
// projectorSize and the card be given longer side first. The core detectors take usable options as given, so
// the steps check here first and fail, saying which, instead.
core::Status checkDetectorOptions(const CalibrationOptions& options, cv::Size projectorSize);

// The "table" calibration step, the paper's quick set-up on top of the projector-camera pair known from
// `current`: the texture of the captured pairs (averaged) shows the projected chessboard and the card's
// stripe in the border; their corners give table_to_camera and table_to_projector (core::setUpTable), and the
// display is fitted undistorted into the lit area (core::fitDisplayToTable). Fails, saying why, without a
// current calibration, when the board or the card is not found, or when the result does not fit.
EstimateResult setUpTableFromPairs(const std::vector<core::FramePair>& pairs,
                                   const std::optional<core::Calibration>& current,
                                   const CalibrationOptions& options);

// The same on one texture (8-bit gray or BGR, the scene without the code) under the `current` pair; the
// estimate's scene is that texture in gray.
EstimateResult setUpTableFromTexture(const cv::Mat& texture, const core::Calibration& current,
                                     const CalibrationOptions& options);

// The calibration of `pair` over the table seen in `table` (the chessboard's corners and the card's, raw
// camera pixels): the table's pose (core::setUpTable) and the display of displaySize fitted undistorted into
// the lit area (core::fitDisplayToTable); RMS of the set-up. Fails, saying why, when either does not work
// out.
EstimateResult calibrationOverTable(const core::ProjectorCameraPair& pair, const core::PlaneView& table,
                                    cv::Size2d cardSizeMm, cv::Size displaySize);

// The table step as the calibration job runs it: shows the board (tableSetUpChessboard) on white, captures
// options.pairsPerStep pairs and sets the table up from them (setUpTableFromPairs). After another step of the
// same job it instead waits until the scene differs from the one that step measured last
// (StepContext::previousScene) and holds still, and uses the still spell.
EstimateResult setUpTableStep(const StepContext& context);

}  // namespace everytouch::service
