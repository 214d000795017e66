#include "service/frame_sources.h"

#include <cstdlib>

#include "io/aravis_source.h"
#include "io/input_error.h"
#include "io/overlay_projector.h"
#include "io/replay_source.h"
#include "io/sim_projector.h"
#include "io/sim_source.h"
#include "io/v4l2_source.h"
#include "io/wayland_overlay_projector.h"
#include "io/window_projector.h"

namespace everytouch::service {

namespace {

void openCameraProjector(const ProjectorConfig& projector, const std::filesystem::path& stateDirectory,
                         OpenedRig& rig) {
    if (projector.output == ProjectorOutput::Overlay) {
        // A Wayland session's X server (Xwayland) draws its windows through the Wayland compositor, so
        // the compositor's own overlay layer is taken wherever there is one.
        const char* wayland = std::getenv("WAYLAND_DISPLAY");
        if (wayland && *wayland) {
            auto overlay = std::make_unique<io::WaylandOverlayProjector>(projector.display, projector.seed,
                                                                         projector.delta, stateDirectory);
            rig.pattern = overlay->pattern();
            rig.projector = std::move(overlay);
            return;
        }
        auto overlay = std::make_unique<io::OverlayProjector>(projector.display, projector.seed,
                                                              projector.delta, stateDirectory);
        rig.pattern = overlay->pattern();
        rig.projector = std::move(overlay);
        return;
    }
    if (projector.output != ProjectorOutput::Window)
        return;
    auto window = std::make_unique<io::WindowProjector>(projector.display, projector.seed, projector.delta,
                                                        stateDirectory);
    rig.pattern = window->pattern();
    rig.projector = std::move(window);
}

}  // namespace

OpenedRig openRig(const io::RigSpec& spec, bool fast, const io::CameraSettings& camera,
                  const ProjectorConfig& projector, const std::filesystem::path& stateDirectory) {
    OpenedRig rig;
    switch (spec.kind) {
        case io::RigSpec::Kind::Replay:
            rig.source = std::make_unique<io::ReplaySource>(spec.target, !fast);
            return rig;
        case io::RigSpec::Kind::Sim: {
            auto source = std::make_unique<io::SimSource>(spec, !fast);
            rig.projector = std::make_unique<io::SimProjector>(*source);
            rig.source = std::move(source);
            return rig;
        }
        case io::RigSpec::Kind::Aravis:
            rig.source = std::make_unique<io::AravisSource>("--rig " + spec.toString(), spec.target, camera);
            openCameraProjector(projector, stateDirectory, rig);
            return rig;
        case io::RigSpec::Kind::V4l2:
            rig.source = std::make_unique<io::V4l2Source>("--rig " + spec.toString(), spec.target, camera);
            openCameraProjector(projector, stateDirectory, rig);
            return rig;
    }
    throw io::InputError("--rig " + spec.toString(), "", "unknown rig kind");
}

}  // namespace everytouch::service
