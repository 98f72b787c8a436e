//! The uniforms the shaders read (shaders/diffraction.wgsl's `Globals` and
//! `Material`; shaders/baselines.wgsl's `Baseline`), mirrored by hand and
//! checked against the WGSL by naga's reflection in the tests below, the
//! vertex layout, and the spectrum buffer. `Material` holds what the default
//! technique (the response map, the environment) and every mesh read; the
//! baselines' series, crop, kernel and tables are their own uniform, bound
//! by their pipelines only.

use super::{Mode, Settings, MAX_LIGHTS};
use sunbeam_frame::spectral::Samples;
use sunbeam_optics::cie;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct Vertex {
    pub(super) pos: [f32; 3],
    pub(super) normal: [f32; 3],
    pub(super) tangent: [f32; 4],
    /// TEXCOORD_0 and the glTF TANGENT (UV frame, w = handedness) of a mesh
    /// with scale maps; zero otherwise (the shader does not read them).
    pub(super) uv: [f32; 2],
    pub(super) uv_tangent: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct Globals {
    pub(super) view_proj: [[f32; 4]; 4],
    pub(super) eye: [f32; 4],
    pub(super) lights: [[f32; 4]; MAX_LIGHTS],
    /// rgb: each light's linear sRGB colour (scene `lights[].color`).
    pub(super) light_colors: [[f32; 4]; MAX_LIGHTS],
    pub(super) xyz_to_rgb: [[f32; 4]; 3],
    pub(super) background: [f32; 4],
    pub(super) n_lights: u32,
    /// The rows of one band of the grid's walk targets ([`super::cells_rate`]
    /// `Bands`; 0 without a grid).
    pub(super) cells_band: u32,
    pub(super) curve: u32,
    pub(super) output: u32,
    pub(super) exposure_scale: f32,
    pub(super) n_lambda: u32,
    /// Samples per pixel of the colour target (the shader tells covered pixels from silhouettes).
    pub(super) msaa: u32,
    /// K >= 1: the cells' centre pass ran (after the coarse grid of K x K
    /// pixels for K > 1; [`super::cells_rate`]); 0: every fragment walks
    /// them.
    pub(super) cells_rate: u32,
    /// 1: the cells' grid serves grazing views too (a tile of edge
    /// refinement, [`super::FrameState::sub_pixel`] > 1), else 0.
    pub(super) cells_grazing: u32,
    pub(super) _pad: [u32; 3],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Default)]
pub(super) struct MaterialU {
    pub(super) base: [f32; 4],
    /// 1 when the mesh diffracts (it has a pack; 0 in the Lambert mode).
    pub(super) has_pack: u32,
    /// 1 when the mesh's scale maps are bound (shaders/scales.wgsl).
    pub(super) scales_on: u32,
    pub(super) mask_sx: f32,
    pub(super) mask_sy: f32,
    /// The skin's refractive index (scene `meshes[].ior`).
    pub(super) ior: f32,
    /// What G is divided by: `sunbeam_optics::gain::Material::norm` (1
    /// absolute, F(0) relative).
    pub(super) norm: f32,
    pub(super) resp_on: u32,
    pub(super) resp_n_theta: f32,
    pub(super) resp_n_rho: f32,
    pub(super) resp_n_s: f32,
    pub(super) resp_r0: f32,
    pub(super) resp_rho_scale: f32,
    pub(super) resp_footprint: u32,
    /// The scale maps' wraps: bits 0-1 the normal map's REPEAT along s and
    /// t, bits 2-3 the orientation map's.
    pub(super) scales_wrap: u32,
    /// 1 when the frame's pass reads the cells' pre-passes at this mesh's
    /// fragments and the pre-passes shade it: `reads_centre` in
    /// renderer/mod.rs, the one definition.
    pub(super) reads_cells: u32,
    /// The mesh's index + 1: the cells' grid walk (shaders/default.wgsl
    /// `fs_cells_walk`, one full-screen pass per mesh) walks the grid points
    /// the raster pass marked with it.
    pub(super) cells_id: u32,
    /// The energy bound's table (`sunbeam_optics::energy::EnergyBound::columns`).
    pub(super) energy: [[f32; 4]; 4],
}

/// shaders/baselines.wgsl's `Baseline`: the pack's series, crop, kernel and
/// per-|t| term table (docs/PACK_FORMAT.md "Evaluation") for the per-fragment
/// baselines, and the table baseline's grid.
#[cfg(feature = "baselines")]
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Default)]
pub(super) struct BaselineU {
    pub(super) basis: u32,
    pub(super) model: u32,
    pub(super) taps: u32,
    pub(super) crop_w: u32,
    pub(super) crop_h: u32,
    pub(super) kx: i32,
    pub(super) ky: i32,
    pub(super) terms: u32,
    pub(super) fixed_terms: u32,
    pub(super) n_table: u32,
    pub(super) bin_scale_um: [f32; 2],
    pub(super) half_range_um: f32,
    pub(super) beta: f32,
    pub(super) sigma_bins: [f32; 2],
    pub(super) kb_norm: f32,
    pub(super) table_dt: f32,
    pub(super) tab_nu: u32,
    pub(super) tab_nv: u32,
    pub(super) tab_nw: u32,
    pub(super) tab_u0: f32,
    pub(super) tab_du: f32,
    pub(super) tab_dv: f32,
    pub(super) tab_w0: f32,
    pub(super) tab_dw: f32,
    /// The window's sigma in um (window model: R_U in the direct mode), 0 = R.
    pub(super) window_sigma_um: f32,
    pub(super) _b: u32,
}

/// Wavelength samples of a mode: the thesis' 5 nm steps, else `lambda_samples` midpoints.
pub(super) fn spectral_samples(settings: &Settings) -> Samples {
    match settings.mode {
        Mode::Thesis => Samples::stepped(380, 780, 5),
        _ => Samples::uniform(settings.lambda_samples.max(1), cie::DEFAULT_RANGE_NM),
    }
}

/// The spectrum buffer of the shader: XYZ weight and 1 / lambda in 1/um per sample.
pub(super) fn spectrum_table(samples: &Samples) -> Vec<[f32; 4]> {
    samples
        .0
        .iter()
        .map(|s| {
            [
                s.weight[0] as f32,
                s.weight[1] as f32,
                s.weight[2] as f32,
                (1e-6 / s.lambda_m) as f32,
            ]
        })
        .collect()
}

#[cfg(test)]
mod layout_tests {
    //! The uniform structs mirror the WGSL by hand; naga's reflection of the
    //! shader checks every shared member's offset and the total size, so the two
    //! cannot drift (a field added on one side only fails here).
    use super::super::SHADER;
    use super::{Globals, MaterialU};
    use std::mem::{offset_of, size_of};

    fn wgsl_struct(src: &str, name: &str) -> (u32, Vec<(String, u32)>) {
        let module = naga::front::wgsl::parse_str(src).expect("the shader parses");
        for (_, ty) in module.types.iter() {
            if ty.name.as_deref() == Some(name) {
                if let naga::TypeInner::Struct { members, span } = &ty.inner {
                    return (
                        *span,
                        members
                            .iter()
                            .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                            .collect(),
                    );
                }
            }
        }
        panic!("struct {name} not found in the WGSL");
    }

    fn check(name: &str, size: usize, rust: &[(&str, usize)]) {
        check_in(SHADER, name, size, rust)
    }

    fn check_in(src: &str, name: &str, size: usize, rust: &[(&str, usize)]) {
        let (span, members) = wgsl_struct(src, name);
        assert_eq!(span as usize, size, "{name}: WGSL size vs Rust size");
        let mut matched = 0;
        for (field, off) in rust {
            let Some((_, w)) = members.iter().find(|(n, _)| n == field) else {
                panic!("{name}.{field} is not in the WGSL struct");
            };
            assert_eq!(
                *w as usize, *off,
                "{name}.{field}: WGSL offset vs Rust offset"
            );
            matched += 1;
        }
        let named = members.iter().filter(|(n, _)| !n.starts_with('_')).count();
        assert_eq!(
            matched, named,
            "{name}: every named WGSL member has a Rust twin"
        );
    }

    #[test]
    fn globals_match_the_wgsl() {
        macro_rules! f {
            ($($n:ident),*) => { [$((stringify!($n), offset_of!(Globals, $n))),*] };
        }
        check(
            "Globals",
            size_of::<Globals>(),
            &f!(
                view_proj,
                eye,
                lights,
                light_colors,
                xyz_to_rgb,
                background,
                n_lights,
                cells_band,
                curve,
                output,
                exposure_scale,
                n_lambda,
                msaa,
                cells_rate,
                cells_grazing
            ),
        );
    }

    #[test]
    fn material_matches_the_wgsl() {
        macro_rules! f {
            ($($n:ident),*) => { [$((stringify!($n), offset_of!(MaterialU, $n))),*] };
        }
        check(
            "Material",
            size_of::<MaterialU>(),
            &f!(
                base,
                has_pack,
                scales_on,
                mask_sx,
                mask_sy,
                ior,
                norm,
                resp_on,
                resp_n_theta,
                resp_n_rho,
                resp_n_s,
                resp_r0,
                resp_rho_scale,
                resp_footprint,
                scales_wrap,
                reads_cells,
                cells_id,
                energy
            ),
        );
    }

    #[cfg(feature = "baselines")]
    #[test]
    fn baseline_matches_the_wgsl() {
        use super::super::baselines::BASELINE_SHADER;
        use super::BaselineU;
        macro_rules! f {
            ($($n:ident),*) => { [$((stringify!($n), offset_of!(BaselineU, $n))),*] };
        }
        check_in(
            BASELINE_SHADER,
            "Baseline",
            size_of::<BaselineU>(),
            &f!(
                basis,
                model,
                taps,
                crop_w,
                crop_h,
                kx,
                ky,
                terms,
                fixed_terms,
                n_table,
                bin_scale_um,
                half_range_um,
                beta,
                sigma_bins,
                kb_norm,
                table_dt,
                tab_nu,
                tab_nv,
                tab_nw,
                tab_u0,
                tab_du,
                tab_dv,
                tab_w0,
                tab_dw,
                window_sigma_um
            ),
        );
    }

    #[test]
    fn environment_uniforms_match_the_wgsl() {
        use crate::env::{EnvGlobals, EnvProposalU};
        macro_rules! f {
            ($t:ty; $($n:ident),*) => { [$((stringify!($n), offset_of!($t, $n))),*] };
        }
        check(
            "EnvGlobals",
            size_of::<EnvGlobals>(),
            &f!(EnvGlobals; basis_to_rgb, sun_dir, sun_rgb, sun_t, sun_b, table_w, table_h, frame, on, has_sun, samples, estimator, chain_levels, irr_ior, table_phase, hot_footprint, frame_share, frame_sample),
        );
        check(
            "EnvProposal",
            size_of::<EnvProposalU>(),
            &f!(EnvProposalU; offsets, pw, ph, top, n_s, n_theta, n_rho, n_s_f, r0, rho_scale, on, has_sun, n_cells),
        );
    }

    #[test]
    fn accumulation_uniforms_match_the_wgsl() {
        use crate::accum::{AccU, ResolveU, ACCUMULATE_WGSL, RESOLVE_WGSL};
        macro_rules! f {
            ($t:ty; $($n:ident),*) => { [$((stringify!($n), offset_of!($t, $n))),*] };
        }
        check_in(
            ACCUMULATE_WGSL,
            "AccU",
            size_of::<AccU>(),
            &f!(AccU; width, height, count, sample),
        );
        check_in(
            RESOLVE_WGSL,
            "ResolveU",
            size_of::<ResolveU>(),
            &f!(ResolveU; width, inv_n, curve, output),
        );
    }
}
