#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include <arv.h>
#include <opencv2/core/mat.hpp>

namespace everytouch::test {

// A GigE Vision camera on 127.0.0.1: Aravis's fake camera, served by this process over the real GVCP and GVSP
// protocols on the loopback interface, whose images come from `fill`. A camera process talks to it as to
// any GigE camera at that address. Only one can run at a time on a machine (GVCP's port): tests that use it
// share the ctest resource lock "gige_loopback".
class FakeGigeCamera {
public:
    // Writes the image of camera frame `frameId` into `image`, a view of the camera's buffer: CV_8UC1 of the
    // camera's size for 8-bit formats (Mono8, Bayer), CV_8UC3 for RGB8. Runs on the camera's own thread.
    using Fill = std::function<void(std::uint64_t frameId, ArvPixelFormat format, cv::Mat& image)>;

    // The camera's image is `size` (its region on a sensor of 2048 x 2048 pixels).
    FakeGigeCamera(cv::Size size, Fill fill);

    static constexpr const char* kAddress = "127.0.0.1";
    ~FakeGigeCamera();
    FakeGigeCamera(const FakeGigeCamera&) = delete;
    FakeGigeCamera& operator=(const FakeGigeCamera&) = delete;

    // A pulse on the camera's software trigger, as its TriggerSoftware command gives.
    void triggerSoftware();

    // The camera goes away at once, as when its cable is pulled.
    void unplug();

private:
    static void onFill(ArvBuffer* buffer, void* self, guint32 exposureUs, guint32 gain,
                       ArvPixelFormat format);

    Fill fill_;
    ArvGvFakeCamera* camera_ = nullptr;
};

}  // namespace everytouch::test
