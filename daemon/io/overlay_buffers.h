#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace everytouch::io {

// The two buffers a code overlay alternates between, and the ones new images replaced, kept while the display
// server may still show them. A buffer attached in a commit is shown until a later commit attaches another,
// and it is certainly no longer read once that later commit's frame has been shown: a replaced pair goes
// then, however many pairs came in between. A pair never attached goes as soon as it is replaced.
// `Buffer` owns one buffer (a move-only handle); the overlay draws one commit at a time, waiting for each
// frame before the next.
template <typename Buffer>
class OverlayBuffers {
public:
    void replace(Buffer positive, Buffer negative) {
        if (currentAttached_) {
            retired_.push_back(std::move(current_[0]));
            retired_.push_back(std::move(current_[1]));
            // The commit waiting for its frame may show a buffer just retired.
            retireOnFrame_ = false;
        }
        current_[0] = std::move(positive);
        current_[1] = std::move(negative);
        currentAttached_ = false;
    }

    // The buffer for `polarity` (0 or 1) in the commit being made.
    const Buffer& attach(int polarity) {
        currentAttached_ = true;
        retireOnFrame_ = !retired_.empty();
        return current_[polarity];
    }

    // The last commit's frame was shown.
    void frameShown() {
        if (!retireOnFrame_)
            return;
        retired_.clear();
        retireOnFrame_ = false;
    }

    // Replaced buffers kept while they may still be shown.
    std::size_t retiredCount() const { return retired_.size(); }

private:
    Buffer current_[2]{};
    bool currentAttached_ = false;
    std::vector<Buffer> retired_;
    bool retireOnFrame_ = false;
};

}  // namespace everytouch::io
