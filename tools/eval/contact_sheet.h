#pragma once

#include <cstddef>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "eval/fingertip_scoring.h"
#include "eval/segmentation_evaluation.h"
#include "eval/segmentation_methods.h"
#include "io/recording.h"

namespace everytouch::eval {

// A contact sheet in the manner of the paper's Fig. 13: one row per pair, the columns its texture T, the
// truth mask and each method's mask with its precision and recall. On the masks white is hand in both, red
// marked but not hand, blue hand missed; green crosses are the fingertips found on the mask, yellow circles
// truth.csv's fingers (radius: the match radius).
struct ContactSheetOptions {
    int rows = 4;        // pairs shown, spread evenly over the pairs with a hand in the truth
    double scale = 0.5;  // of a camera frame in a cell; half keeps four methods within a screen's width

    std::optional<std::string> validate() const;
};

// positions: candidates for the rows (newer frame of each pair), in time order; the rows are taken evenly
// from them. Runs the methods again on those pairs.
cv::Mat renderContactSheet(const io::Recording& recording, const std::vector<std::size_t>& positions,
                           const std::vector<SegmentationMethod>& methods,
                           const FingertipFinder& findFingertips, const TruthToCamera& truthToCamera,
                           const ContactSheetOptions& options);

}  // namespace everytouch::eval
