#include "support/fake_gige_camera.h"

#include <stdexcept>

namespace everytouch::test {

FakeGigeCamera::FakeGigeCamera(cv::Size size, Fill fill) : fill_(std::move(fill)) {
    camera_ = arv_gv_fake_camera_new(kAddress, "everytouch-test");
    if (!camera_ || !arv_gv_fake_camera_is_running(camera_)) {
        unplug();
        throw std::runtime_error(std::string("the fake GigE Vision camera does not run on ") + kAddress);
    }
    ArvFakeCamera* fake = arv_gv_fake_camera_get_fake_camera(camera_);
    arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_WIDTH, static_cast<guint32>(size.width));
    arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_HEIGHT, static_cast<guint32>(size.height));
    arv_fake_camera_set_fill_pattern(fake, onFill, this);
}

FakeGigeCamera::~FakeGigeCamera() {
    unplug();
}

void FakeGigeCamera::triggerSoftware() {
    arv_fake_camera_write_register(arv_gv_fake_camera_get_fake_camera(camera_),
                                   ARV_FAKE_CAMERA_REGISTER_TRIGGER_SOFTWARE, 1);
}

void FakeGigeCamera::unplug() {
    if (camera_)
        g_object_unref(camera_);
    camera_ = nullptr;
}

void FakeGigeCamera::onFill(ArvBuffer* buffer, void* self, guint32, guint32, ArvPixelFormat format) {
    auto* camera = static_cast<FakeGigeCamera*>(self);
    const int channels = static_cast<int>(ARV_PIXEL_FORMAT_BIT_PER_PIXEL(format) / 8);
    if (channels != 1 && channels != 3)
        return;
    // The fake camera checked that the buffer holds width x height pixels of the format.
    void* data = const_cast<void*>(arv_buffer_get_data(buffer, nullptr));
    cv::Mat image(arv_buffer_get_image_height(buffer), arv_buffer_get_image_width(buffer), CV_8UC(channels),
                  data);
    camera->fill_(arv_buffer_get_frame_id(buffer), format, image);
}

}  // namespace everytouch::test
