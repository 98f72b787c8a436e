// The display transform, written once for every pass that writes display
// values (diffraction.wgsl's `display`, resolve.wgsl, background.wgsl):
// sunbeam_optics::colour::display_encode, per channel.

fn sb_srgb_oetf(y: f32) -> f32 {
    let c = clamp(y, 0.0, 1.0);
    if (c <= 0.0031308) {
        return 12.92 * c;
    }
    return 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

fn sb_srgb_eotf(v: f32) -> f32 {
    let c = clamp(v, 0.0, 1.0);
    if (c <= 0.04045) {
        return c / 12.92;
    }
    return pow((c + 0.055) / 1.055, 2.4);
}

// One linear channel, exposure applied, to what the target stores: NaN and
// negatives to 0, the tone curve (`curve` 0 clamp, 1 Reinhard), the sRGB
// OETF, then back to linear for an sRGB-format target (`output` 1, which
// encodes on store).
fn sb_display_channel(linear: f32, curve: u32, output: u32) -> f32 {
    var x = linear;
    if (x != x) {
        x = 0.0;
    }
    x = max(x, 0.0);
    if (curve == 0u) {
        x = min(x, 1.0);
    } else {
        x = x / (1.0 + x);
    }
    var e = sb_srgb_oetf(x);
    if (output == 1u) {
        e = sb_srgb_eotf(e);
    }
    return e;
}

