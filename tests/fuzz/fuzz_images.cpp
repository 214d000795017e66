// The images of a recording (docs/file-formats.md) as everytouchd --rig replay and everytouch-eval read them:
// the input is both the frame (frames/000000.png) and the hand mask (masks/000000.png) of a recording whose
// rig.yml (a 64 x 48 camera), pattern and frames.csv are written once. An image may only give io::InputError;
// anything else is a finding, and so is an image that makes the reader allocate far beyond the camera's size
// (libFuzzer's -rss_limit_mb).
#include <cstdint>
#include <filesystem>

#include "fuzz_input.h"
#include "io/input_error.h"
#include "io/recording.h"

namespace {

constexpr const char* kRig =
    "%YAML:1.0\n"
    "---\n"
    "format: everytouch-recording\n"
    "version: 1\n"
    "camera_size: [ 64, 48 ]\n"
    "camera_matrix: !!opencv-matrix\n"
    "   rows: 3\n"
    "   cols: 3\n"
    "   dt: d\n"
    "   data: [ 8.0081e+01, 0., 3.1500e+01, 0., 8.0081e+01, 2.3500e+01, 0., 0., 1. ]\n"
    "camera_distortion: !!opencv-matrix\n"
    "   rows: 1\n"
    "   cols: 5\n"
    "   dt: d\n"
    "   data: [ 0., 0., 0., 0., 0. ]\n"
    "projector_size: [ 640, 480 ]\n"
    "projector_matrix: !!opencv-matrix\n"
    "   rows: 3\n"
    "   cols: 3\n"
    "   dt: d\n"
    "   data: [ 950., 0., 3.1950000000000000e+02, 0., 950., 150., 0., 0., 1. ]\n"
    "table_to_camera: !!opencv-matrix\n"
    "   rows: 4\n"
    "   cols: 4\n"
    "   dt: d\n"
    "   data: [ 9.9922465582450248e-01, -1.7452012230585165e-02,\n"
    "       3.5291846955183330e-02, 1.7452012230582525e-01, 0.,\n"
    "       -8.9638859708298380e-01, -4.4326908646960739e-01,\n"
    "       8.9638859708298355e+00, 3.9371146699132060e-02,\n"
    "       4.4292540036523503e-01, -8.9569358740525307e-01,\n"
    "       5.0355696628189833e+02, 0., 0., 0., 1. ]\n"
    "table_to_projector: !!opencv-matrix\n"
    "   rows: 4\n"
    "   cols: 4\n"
    "   dt: d\n"
    "   data: [ 9.9878010055351008e-01, 2.0506826468149865e-02,\n"
    "       -4.4919715120709233e-02, -3.5527136788005009e-14,\n"
    "       -4.6315370374729083e-03, -8.6677274483604605e-01,\n"
    "       -4.9868182007574480e-01, 4.7487149245209736e+01,\n"
    "       -4.9161566319544811e-02, 4.9828152572375400e-01,\n"
    "       -8.6562039111807942e-01, 5.0405353947429347e+02, 0., 0., 0., 1. ]\n"
    "display_size: [ 640, 480 ]\n"
    "display_to_projector: !!opencv-matrix\n"
    "   rows: 3\n"
    "   cols: 3\n"
    "   dt: d\n"
    "   data: [ -9.6724473144643275e-01, 1.8521417734399503e-01,\n"
    "       6.3140637956554087e+02, 1.2204601390568214e-02,\n"
    "       -7.7606034558596282e-01, 4.1945592119874419e+02,\n"
    "       5.0958669689220090e-05, 5.1649623033883240e-04, 1. ]\n"
    "delta: 10\n"
    "frame_rate: 120.\n"
    "pattern: \"pattern.png\"\n";

const std::filesystem::path& recordingDirectory() {
    static const std::filesystem::path directory = [] {
        const std::filesystem::path& path = everytouch::fuzz::recordingSkeleton();
        everytouch::fuzz::writeFile(path / "rig.yml", kRig);
        everytouch::fuzz::writeFile(path / "frames.csv", "index,timestamp_us,polarity\n0,0,1\n");
        for (const std::filesystem::path& image :
             {everytouch::io::Recording::framePath(path, 0), everytouch::io::Recording::maskPath(path, 0)})
            everytouch::fuzz::writeFile(image, "");
        return path;
    }();
    return directory;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace everytouch;
    const std::filesystem::path& directory = recordingDirectory();
    // Opened once: its images are read from their files each time one is loaded.
    static const io::Recording recording = io::Recording::open(directory);
    const std::string_view image(reinterpret_cast<const char*>(data), size);
    fuzz::writeFile(io::Recording::framePath(directory, 0), image);
    fuzz::writeFile(io::Recording::maskPath(directory, 0), image);
    try {
        (void)recording.loadFrame(0);
    } catch (const io::InputError&) {
    }
    try {
        (void)recording.loadMask(0);
    } catch (const io::InputError&) {
    }
    return 0;
}
