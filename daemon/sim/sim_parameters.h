#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <opencv2/core/types.hpp>

namespace everytouch::sim {

// The table's surface, as in the paper's Fig. 15.
enum class SurfaceKind { Gray, Yellow, Artifacts };

// How the sensor sees colour: a Bayer colour filter array demosaiced to BGR (the paper's camera), three
// colour values per pixel (an idealised colour camera), or a monochrome sensor.
enum class CameraColour { Bayer, Rgb, Mono };

// Skin reflectance presets, light to dark.
enum class SkinTone { Light, Medium, Tan, Dark };

// Every parameter of the simulated rig. Defaults describe the paper's rig (section III): a 640x480 DLP
// projector at 120 Hz, a 648x488 camera at 120 fps with a 6 mm lens and 7.4 um pixels triggered by the
// projector, about 500 mm working distance, a projected area of about 15", projector and camera a few
// centimetres apart, both looking down at an angle.
//
// Table frame: x, y on the table in mm, z up. The rig stands on the far side of the table (y < 0) and looks
// towards the user, who sits at +y; the user's hands enter the scene from +y. Light is measured in lux of
// illuminance on the table; "radiance" below means illuminance times albedo (lux), which the camera turns
// into electrons with `sensitivity`.
struct SimParameters {
    // --- session ---
    std::string scenario = "demo";    // grid35, drag, multitouch, hover, palm, idle, demo, table-setup,
                                      // pair-calibration
    std::uint64_t seed = 1;           // every random choice (pattern, content, motion, noise) follows from it
    double startS = 0.0;              // the stream starts this many seconds into the session
    std::optional<double> durationS;  // the stream ends after this many seconds; endless when not set
    std::string content = "auto";     // procedural content kind (see content.h) or "auto": the scenario's own
    // --- camera faults (what SimSource delivers; the session goes on meanwhile) ---
    std::optional<double> stallS;  // no frame comes from this session time on, for stallDurationS
    double stallDurationS = 1.0;
    std::optional<double> wrongSizeS;  // from this session time the frames are the sensor's centre quarter
    double wrongSizeDurationS = 0.5;   // (a region changed by someone else), for this long
    // --- a knock: the camera moves after the calibration, which stays as it was (as a real rig's does) ---
    std::optional<double> knockS;  // at this session time the camera turns by knockDeg about an axis through
    double knockDeg = 0.5;         // its centre and shifts by knockMm, axis and direction random (seeded)
    double knockMm = 2.0;
    // --- the table slides on the floor: it moves and turns in its own plane under the rig, which stays ---
    std::optional<double> tableShiftS;  // at this session time the table slides by tableShiftMm in a random
    double tableShiftMm = 5.0;          // (seeded) direction and turns by tableShiftDeg about the vertical
    double tableShiftDeg = 1.0;         // through the display's centre
    // --- the table tilts (a leg on a cable): its plane turns under the rig, which stays ---
    std::optional<double> tableTiltS;  // at this session time the table turns by tableTiltDeg about a level
    double tableTiltDeg = 1.0;         // axis through the display's centre, its direction random (seeded)
    // The projector's image creeps across the table at this rate, projector pixels per minute, in a random
    // (seeded) direction, as a warming projector's does; the calibration stays as it was. 0: it holds.
    double driftPxPerMin = 0.0;

    // --- geometry ---
    cv::Size cameraSize{648, 488};                         // sensor, pixels
    double cameraFocalMm = 6.0;                            // lens focal length
    double cameraPixelUm = 7.4;                            // pixel pitch
    Eigen::Vector3d cameraPosition{-20.0, -215.0, 455.0};  // optical centre, table mm
    Eigen::Vector3d cameraTarget{0.0, 10.0, 0.0};          // table point on the optical axis
    cv::Size projectorSize{640, 480};                      // DLP panel, pixels
    double projectorFocalPx = 950.0;                       // focal length, panel pixels (throw ratio ~1.5)
    double projectorPrincipalRowPx = 150.0;  // principal point row: projectors' lenses are offset, so the
                                             // image lies off the optical axis (239.5 would centre it)
    Eigen::Vector3d projectorPosition{25.0, -210.0, 460.0};  // optical centre, table mm
    Eigen::Vector3d projectorTarget{0.0, 0.0, 0.0};          // table point hit by the panel's centre pixel
    cv::Size displaySize{640, 480};                          // the desktop image, pixels
    bool keystoneCorrection =
        true;  // the display fills the largest upright 4:3 rectangle inside the projected
               // quadrilateral (the paper's H_TP); otherwise it is the panel itself

    // --- timing and code ---
    double frameRate = 120.0;  // projector refresh = camera frame rate, Hz; frame k shows I (k even) or I'
    int delta = 10;            // code amplitude, projector digital levels (paper: 10)

    // --- projector photometry ---
    double projectorWhiteLux = 150.0;  // illuminance of full white at the display centre (a ~10 lm DLP pico)
    double projectorGamma = 2.2;       // light = black + (1 - black) * (level / 255)^gamma
    double projectorBlackLevel = 0.002;    // light at level 0 as a fraction of white (contrast 500:1)
    double projectorCornerFalloff = 0.85;  // relative illuminance of the panel's corners (lens vignetting)
    double projectorDefocusPx = 0.5;  // Gaussian sigma of the projector's blur on the table, panel pixels

    // --- ambient light ---
    double ambientLux = 150.0;                       // room light on the table ("normal"; "dark": 3)
    Eigen::Vector3d ambientColour{1.0, 0.92, 0.78};  // relative R, G, B of the room light (warm white)
    std::optional<double> ambientChangeLux;          // the room light changes to this level ...
    double ambientChangeAtS = 20.0;                  // ... at this time into the session, seconds

    // --- table surface ---
    SurfaceKind surface = SurfaceKind::Gray;  // gray, yellow or artifacts

    // --- hand ---
    SkinTone skinTone = SkinTone::Medium;  // skin reflectance preset
    double handScale = 1.0;                // hand size relative to an average adult hand (finger ~16 mm wide)
    Eigen::Vector3d skinScatterMm{1.0, 0.55, 0.35};  // subsurface scattering: Gaussian sigma of the light's
                                                     // spread inside skin for R, G, B, mm
    double skinScatterFraction = 0.6;  // fraction of the light reflected by skin after scattering inside it

    // --- camera ---
    CameraColour cameraColour = CameraColour::Bayer;  // bayer, rgb or mono
    double sensitivity = 14000.0;  // electrons per lux-second for albedo 1 at the image centre (f/1.4 lens,
                                   // 7.4 um pixel, quantum efficiency 0.5)
    Eigen::Vector3d channelResponse{0.85, 1.0, 0.8};  // relative R, G, B sensitivity of the colour filters
    double fullWellElectrons = 12000.0;               // saturation charge of one pixel
    double readNoiseElectrons = 12.0;                 // read noise, electrons rms
    double gainDb = 0.0;                              // analogue gain; 0 dB puts the full well at 255 DN
    std::optional<double> exposureMs;  // exposure time; when not set it is metered once at the start so that
                                       // white content on the table reaches `autoExposureLevel`
    double maxExposureMs = 7.5;        // longest exposure that fits a 120 Hz frame
    double autoExposureLevel = 0.8;    // metering target as a fraction of full scale
    double blackLevelDn = 1.0;         // offset the camera adds before quantisation, DN
    double prnu = 0.005;               // photo-response non-uniformity, relative rms (fixed per pixel)
    double cameraDefocusPx = 0.5;      // Gaussian sigma of the camera's blur, camera pixels
    double vignettingPower = 3.0;      // relative illumination falls as cos(field angle)^power
    int pixelSamples = 3;  // the table image is integrated over each camera pixel with n x n samples
    int motionSamples =
        5;  // most instants a moving hand is rendered at within one exposure (motion blur):
            // one per camera pixel it travels, odd; 1 renders every frame at mid-exposure only

    // The first problem found, naming the spec key of the faulty parameter; nothing when usable.
    std::optional<std::string> validate() const;
};

}  // namespace everytouch::sim
