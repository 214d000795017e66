#include "io/overlay_buffers.h"

#include <set>

#include <gtest/gtest.h>

namespace everytouch::io {
namespace {

// A buffer that says when it goes; ids are 10 * image + polarity.
struct TrackedBuffer {
    TrackedBuffer() = default;
    TrackedBuffer(int id, std::set<int>& released) : id(id), released(&released) {}
    TrackedBuffer(TrackedBuffer&& other) noexcept : id(other.id), released(other.released) {
        other.released = nullptr;
    }
    TrackedBuffer& operator=(TrackedBuffer&& other) noexcept {
        if (this != &other) {
            release();
            id = other.id;
            released = other.released;
            other.released = nullptr;
        }
        return *this;
    }
    ~TrackedBuffer() { release(); }
    void release() {
        if (released)
            released->insert(id);
        released = nullptr;
    }

    int id = -1;
    std::set<int>* released = nullptr;
};

class OverlayBuffersTest : public ::testing::Test {
protected:
    void replace(int image) { buffers.replace({10 * image, released}, {10 * image + 1, released}); }
    int attach(int polarity) { return buffers.attach(polarity).id; }
    bool isReleased(int id) const { return released.count(id) > 0; }

    std::set<int> released;
    OverlayBuffers<TrackedBuffer> buffers;
};

TEST_F(OverlayBuffersTest, AReplacedPairStaysUntilAFrameShowsTheNewOne) {
    replace(1);
    EXPECT_EQ(attach(0), 10);
    buffers.frameShown();
    EXPECT_EQ(attach(1), 11);
    replace(2);  // 11 waits for its frame
    EXPECT_FALSE(isReleased(10));
    EXPECT_FALSE(isReleased(11));
    buffers.frameShown();  // 11 shown, still on screen until another commit
    EXPECT_FALSE(isReleased(11));
    EXPECT_EQ(attach(0), 20);
    EXPECT_FALSE(isReleased(11));
    buffers.frameShown();
    EXPECT_TRUE(isReleased(10));
    EXPECT_TRUE(isReleased(11));
    EXPECT_EQ(buffers.retiredCount(), 0u);
}

TEST_F(OverlayBuffersTest, TwoPairsWithinOneFrameKeepTheBufferOnScreen) {
    replace(1);
    EXPECT_EQ(attach(0), 10);
    buffers.frameShown();
    replace(2);
    EXPECT_EQ(attach(1), 21);  // 10 still shown until this frame
    replace(3);                // 21 waits for its frame
    replace(4);                // 30 and 31 were never shown
    EXPECT_TRUE(isReleased(30));
    EXPECT_TRUE(isReleased(31));
    EXPECT_FALSE(isReleased(10));
    EXPECT_FALSE(isReleased(21));
    buffers.frameShown();  // 21 on screen
    EXPECT_FALSE(isReleased(21));
    EXPECT_EQ(attach(0), 40);
    buffers.frameShown();
    for (const int id : {10, 11, 20, 21})
        EXPECT_TRUE(isReleased(id)) << id;
    EXPECT_FALSE(isReleased(40));
    EXPECT_FALSE(isReleased(41));
}

TEST_F(OverlayBuffersTest, APairNeverAttachedGoesAtOnce) {
    replace(1);
    replace(2);
    EXPECT_TRUE(isReleased(10));
    EXPECT_TRUE(isReleased(11));
    EXPECT_EQ(buffers.retiredCount(), 0u);
}

}  // namespace
}  // namespace everytouch::io
