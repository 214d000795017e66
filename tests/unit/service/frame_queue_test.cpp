#include "service/frame_queue.h"

#include <thread>

#include <gtest/gtest.h>

namespace everytouch::service {
namespace {

using namespace std::chrono_literals;

QueuedFrame frameNumber(std::uint64_t index) {
    QueuedFrame item;
    item.frame.index = index;
    return item;
}

TEST(FrameQueue, DropsTheOldestFrameWhenFullAndCountsIt) {
    FrameQueue queue(3, FrameQueue::Overflow::DropOldest);
    for (std::uint64_t i = 0; i < 5; ++i)
        ASSERT_TRUE(queue.push(frameNumber(i)));
    EXPECT_EQ(queue.dropped(), 2u);
    QueuedFrame item;
    for (std::uint64_t expected : {2u, 3u, 4u}) {
        ASSERT_EQ(queue.pop(item, 0ms), FrameQueue::PopResult::Item);
        EXPECT_EQ(item.frame.index, expected);
    }
    EXPECT_EQ(queue.pop(item, 10ms), FrameQueue::PopResult::Timeout);
}

TEST(FrameQueue, BlockingProducerWaitsForTheConsumerAndLosesNothing) {
    FrameQueue queue(2, FrameQueue::Overflow::Block);
    std::thread producer([&] {
        for (std::uint64_t i = 0; i < 50; ++i)
            queue.push(frameNumber(i));
        queue.close();
    });
    QueuedFrame item;
    std::uint64_t expected = 0;
    while (queue.pop(item, 5s) == FrameQueue::PopResult::Item)
        EXPECT_EQ(item.frame.index, expected++);
    producer.join();
    EXPECT_EQ(expected, 50u);
    EXPECT_EQ(queue.dropped(), 0u);
}

TEST(FrameQueue, CloseDeliversWhatIsQueuedThenReportsClosed) {
    FrameQueue queue(4, FrameQueue::Overflow::DropOldest);
    queue.push(frameNumber(7));
    queue.close();
    EXPECT_FALSE(queue.push(frameNumber(8)));
    QueuedFrame item;
    ASSERT_EQ(queue.pop(item, 0ms), FrameQueue::PopResult::Item);
    EXPECT_EQ(item.frame.index, 7u);
    EXPECT_EQ(queue.pop(item, 1s), FrameQueue::PopResult::Closed);
}

TEST(FrameQueue, CloseWakesABlockedProducer) {
    FrameQueue queue(1, FrameQueue::Overflow::Block);
    queue.push(frameNumber(0));
    std::thread producer([&] { EXPECT_FALSE(queue.push(frameNumber(1))); });
    queue.close();
    producer.join();
}

}  // namespace
}  // namespace everytouch::service
