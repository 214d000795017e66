#include "service/frame_tap.h"

#include <atomic>
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

namespace everytouch::service {
namespace {

core::FramePair smallPair() {
    core::FramePair pair;
    pair.positive.image = cv::Mat::zeros(4, 4, CV_8UC1);
    pair.negative.image = cv::Mat::zeros(4, 4, CV_8UC1);
    return pair;
}

TEST(FrameTap, HandsTheRequestedPairsOverOnce) {
    FrameTap tap;
    int deliveries = 0;
    std::size_t delivered = 0;
    tap.request(2, [&](std::vector<TappedPair>&& pairs) {
        ++deliveries;
        delivered = pairs.size();
    });
    const core::FramePair pair = smallPair();
    for (int i = 0; i < 4; ++i)
        tap.offer(pair, nullptr);
    EXPECT_EQ(deliveries, 1);
    EXPECT_EQ(delivered, 2u);
}

TEST(FrameTap, ACancelledRequestIsNeverDelivered) {
    FrameTap tap;
    bool delivered = false;
    const FrameTap::Ticket ticket = tap.request(1, [&](std::vector<TappedPair>&&) { delivered = true; });
    tap.cancel(ticket);
    tap.offer(smallPair(), nullptr);
    EXPECT_FALSE(delivered);
}

// Whoever cancels may destroy what `done` uses as soon as cancel returns: a delivery under way on the
// pipeline thread must have ended by then.
TEST(FrameTap, CancelReturnsOnlyOnceADeliveryUnderWayHasEnded) {
    FrameTap tap;
    std::atomic<bool> started{false}, finished{false};
    const FrameTap::Ticket ticket = tap.request(1, [&](std::vector<TappedPair>&&) {
        started = true;
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        finished = true;
    });
    std::thread pipeline([&] { tap.offer(smallPair(), nullptr); });
    while (!started)
        std::this_thread::yield();
    tap.cancel(ticket);
    EXPECT_TRUE(finished);
    pipeline.join();
}

TEST(FrameTap, DoneMayCancelItsOwnTicketWithoutWaitingForItself) {
    FrameTap tap;
    FrameTap::Ticket ticket = 0;
    bool delivered = false;
    ticket = tap.request(1, [&](std::vector<TappedPair>&&) {
        tap.cancel(ticket);
        delivered = true;
    });
    tap.offer(smallPair(), nullptr);
    EXPECT_TRUE(delivered);
}

}  // namespace
}  // namespace everytouch::service
