#include "sim/sim_parameters.h"

#include <cmath>

namespace everytouch::sim {

namespace {

bool positive(double value) {
    return std::isfinite(value) && value > 0.0;
}

bool nonNegative(double value) {
    return std::isfinite(value) && value >= 0.0;
}

bool fraction(double value) {
    return std::isfinite(value) && value >= 0.0 && value <= 1.0;
}

}  // namespace

std::optional<std::string> SimParameters::validate() const {
    if (scenario.empty())
        return "scenario: empty";
    if (!nonNegative(startS))
        return "start: must be a number of seconds >= 0";
    if (durationS && !positive(*durationS))
        return "duration: must be a positive number of seconds";
    if (content.empty())
        return "content: empty";
    if (stallS && !nonNegative(*stallS))
        return "stall: must be a number of seconds >= 0";
    if (!positive(stallDurationS))
        return "stall_s: must be a positive number of seconds";
    if (wrongSizeS && !nonNegative(*wrongSizeS))
        return "wrong_size: must be a number of seconds >= 0";
    if (!positive(wrongSizeDurationS))
        return "wrong_size_s: must be a positive number of seconds";
    if (knockS && !nonNegative(*knockS))
        return "knock: must be a number of seconds >= 0";
    if (!nonNegative(knockDeg) || knockDeg > 10.0)
        return "knock_deg: must be a number of degrees from 0 to 10";
    if (!nonNegative(knockMm) || knockMm > 100.0)
        return "knock_mm: must be a number of millimetres from 0 to 100";
    if (tableShiftS && !nonNegative(*tableShiftS))
        return "table_shift: must be a number of seconds >= 0";
    if (!nonNegative(tableShiftMm) || tableShiftMm > 100.0)
        return "table_shift_mm: must be a number of millimetres from 0 to 100";
    if (!nonNegative(tableShiftDeg) || tableShiftDeg > 10.0)
        return "table_shift_deg: must be a number of degrees from 0 to 10";
    if (tableTiltS && !nonNegative(*tableTiltS))
        return "table_tilt: must be a number of seconds >= 0";
    if (!nonNegative(tableTiltDeg) || tableTiltDeg > 10.0)
        return "table_tilt_deg: must be a number of degrees from 0 to 10";
    if (!nonNegative(driftPxPerMin) || driftPxPerMin > 60.0)
        return "drift_px_per_min: must be a number of projector pixels per minute from 0 to 60";
    if (cameraSize.width < 16 || cameraSize.height < 16)
        return "camera_size: at least 16x16 pixels";
    if (!positive(cameraFocalMm))
        return "camera_focal_mm: must be positive";
    if (!positive(cameraPixelUm))
        return "camera_pixel_um: must be positive";
    if (!cameraPosition.allFinite() || cameraPosition.z() <= 0.0)
        return "camera_position: must be finite and above the table (z > 0)";
    if (!cameraTarget.allFinite())
        return "camera_target: must be finite";
    if (projectorSize.width < 16 || projectorSize.height < 16)
        return "projector_size: at least 16x16 pixels";
    if (!positive(projectorFocalPx))
        return "projector_focal_px: must be positive";
    if (!std::isfinite(projectorPrincipalRowPx))
        return "projector_principal_row_px: must be finite";
    if (!projectorPosition.allFinite() || projectorPosition.z() <= 0.0)
        return "projector_position: must be finite and above the table (z > 0)";
    if (!projectorTarget.allFinite())
        return "projector_target: must be finite";
    if (displaySize.width < 16 || displaySize.height < 16)
        return "display_size: at least 16x16 pixels";
    if (!positive(frameRate) || frameRate > 1000.0)
        return "frame_rate: must be in (0, 1000] Hz";
    if (delta < 1 || delta > 127)
        return "delta: must be in 1..127";
    if (!nonNegative(projectorWhiteLux))
        return "projector_lux: must be >= 0";
    if (!positive(projectorGamma) || projectorGamma > 5.0)
        return "projector_gamma: must be in (0, 5]";
    if (!std::isfinite(projectorBlackLevel) || projectorBlackLevel < 0.0 || projectorBlackLevel >= 1.0)
        return "projector_black: must be in [0, 1)";
    if (!positive(projectorCornerFalloff) || projectorCornerFalloff > 1.0)
        return "projector_corner_falloff: must be in (0, 1]";
    if (!nonNegative(projectorDefocusPx) || projectorDefocusPx > 10.0)
        return "projector_defocus_px: must be in [0, 10]";
    if (!nonNegative(ambientLux))
        return "ambient_lux: must be >= 0";
    if (!ambientColour.allFinite() || (ambientColour.array() < 0.0).any())
        return "ambient_colour: must be three numbers >= 0";
    if (ambientChangeLux && !nonNegative(*ambientChangeLux))
        return "ambient_change_lux: must be >= 0";
    if (!nonNegative(ambientChangeAtS))
        return "ambient_change_s: must be >= 0";
    if (!positive(handScale) || handScale < 0.5 || handScale > 1.5)
        return "hand_scale: must be in [0.5, 1.5]";
    if (!skinScatterMm.allFinite() || (skinScatterMm.array() < 0.0).any() ||
        (skinScatterMm.array() > 10.0).any())
        return "skin_scatter_mm: must be three numbers in [0, 10]";
    if (!fraction(skinScatterFraction))
        return "skin_scatter_fraction: must be in [0, 1]";
    if (!nonNegative(sensitivity))
        return "sensitivity: must be >= 0";
    if (!channelResponse.allFinite() || (channelResponse.array() < 0.0).any())
        return "channel_response: must be three numbers >= 0";
    if (!positive(fullWellElectrons))
        return "full_well: must be positive";
    if (!nonNegative(readNoiseElectrons))
        return "read_noise: must be >= 0";
    if (!std::isfinite(gainDb) || gainDb < 0.0 || gainDb > 48.0)
        return "gain_db: must be in [0, 48]";
    if (!positive(maxExposureMs))
        return "max_exposure_ms: must be positive";
    if (exposureMs && (!positive(*exposureMs) || *exposureMs > 1000.0 / frameRate))
        return "exposure_ms: must be positive and no longer than one frame period";
    if (!positive(autoExposureLevel) || autoExposureLevel > 1.0)
        return "auto_exposure_level: must be in (0, 1]";
    if (!nonNegative(blackLevelDn) || blackLevelDn > 64.0)
        return "black_level_dn: must be in [0, 64]";
    if (!fraction(prnu))
        return "prnu: must be in [0, 1]";
    if (!nonNegative(cameraDefocusPx) || cameraDefocusPx > 10.0)
        return "camera_defocus_px: must be in [0, 10]";
    if (!nonNegative(vignettingPower) || vignettingPower > 8.0)
        return "vignetting_power: must be in [0, 8]";
    if (pixelSamples < 1 || pixelSamples > 8)
        return "pixel_samples: must be in 1..8";
    if (motionSamples < 1 || motionSamples > 15 || motionSamples % 2 == 0)
        return "motion_samples: must be odd, 1..15";
    return std::nullopt;
}

}  // namespace everytouch::sim
