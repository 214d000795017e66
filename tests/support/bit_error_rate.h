#pragma once

#include "core/calibration.h"
#include "core/code_image.h"
#include "support/synthetic_capture.h"

namespace everytouch::test {

// How well the code survives one synthetic capture, over the projector pixels and windows the camera sees
// (through the table's homography, at least one binarisation neighbourhood inside the image).
struct BitErrorFigures {
    double bitErrorRate = 0;        // wrong bits / known bits
    double unknownRate = 0;         // unknown bits / bits
    double tableMismatches = 0;     // mean Hamming distance of a window through the table's homography
    double tableKnown = 0;          // mean known bits of a window
    double elevatedMismatches = 0;  // mean Hamming distance through the homography of a plane 10 mm higher
};

// Renders `scene` (its projectorToCamera must be calibration's table homography), computes S, binarises it
// and compares every visible projector pixel with the pattern (6x6 windows).
BitErrorFigures measureBitErrors(const SyntheticScene& scene, const core::Calibration& calibration,
                                 const core::BinarizationOptions& binarization);

}  // namespace everytouch::test
