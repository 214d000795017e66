#pragma once

#include <opencv2/core/mat.hpp>

namespace everytouch::core {

// The code embedded over a desktop the daemon does not draw: a translucent overlay that the compositor blends
// over everything, one image on the "+" refresh and the other on the "-" refresh. The compositor's "over"
// operator gives result = overlay + (1 - alpha) desktop (premultiplied colours), and with
//   alpha = 2 delta / 255 everywhere,
//   over a 1-bit: white in the "+" image, black in the "-" image,
//   over a 0-bit: mid-grey (127.5) in both,
// the two results are embedCode's I = O + P and I' = O - P for the desktop O (core/embedding.h): their
// difference is 2 delta on 1-bits and 0 on 0-bits whatever the desktop shows, and their average is the
// desktop compressed into [delta, 255 - delta], the same over either bit, so no trace of the pattern stays on
// the table. Swapping white and black between 1- and 0-bits instead would give S = +-delta: a code whose
// 0-bits are not dark, which the code's reading (core/code_image.h) and the segmentation do not expect.
//
// In 8 bits the alpha, 2 delta, and the premultiplied levels 2 delta, 0 and delta are integers, so a
// compositor that rounds (255 - 2 delta) x desktop / 255 rounds it alike in both refreshes: the difference
// stays exact and the average within half a level of the compressed desktop.
//
// bits: CV_8UC1, 0 or 1, one per pixel of the output the overlay covers; delta: 1..127.
// positive, negative: receive CV_8UC4 premultiplied BGRA (in memory the layout of X11's 32-bit ARGB visual
// and of Wayland's ARGB8888 on a little-endian machine); reallocated only when the size changes.
void makeCodeOverlay(const cv::Mat& bits, int delta, cv::Mat& positive, cv::Mat& negative);

}  // namespace everytouch::core
