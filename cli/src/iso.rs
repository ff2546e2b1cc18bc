//! The isosurface options of `ferrovol render` (--mode iso) and the environment light they
//! share with path tracing.

use super::*;

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Debug)]
enum ScatterInside {
    Preview,
    Traced,
}

/// Isosurface options (--mode iso).
#[derive(clap::Args)]
pub(crate) struct IsoArgs {
    /// Light scattered between the isosurfaces (lit by the environment): preview
    /// (transmittance squared, the irradiance cube) or traced (--scatter-samples
    /// directions out of the volume); the first surface becomes opaque, blended with the
    /// scattered light by --fresnel (default 0.04).
    #[arg(long = "scatter-inside", value_enum)]
    scatter_inside: Option<ScatterInside>,
    /// Directions traced per pixel with --scatter-inside traced.
    #[arg(long, default_value_t = 16)]
    scatter_samples: u32,
    /// Multiplies the medium's extinction between the surfaces (0: no absorption).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    absorption: f32,
    /// An isosurface, VALUE[:OPACITY[:R,G,B]] (opacity in (0, 1], default 1; colour
    /// components in [0, 1]); repeat for nested surfaces, e.g. --iso 300 --iso -300:0.3.
    /// Default: the middle of the data range.
    #[arg(long = "iso", value_parser = parse_iso, allow_hyphen_values = true)]
    values: Vec<(f64, Option<f32>, Option<[f32; 3]>)>,
    /// Environment: an equirectangular .hdr/.exr/.png/.jpg image, or `sky` for the built-in
    /// procedural sky (the default).
    #[arg(long)]
    env: Option<String>,
    /// Environment from six square cube faces: +X,-X,+Y,-Y,+Z,-Z image paths, comma-separated.
    #[arg(long, conflicts_with = "env")]
    env_cube: Option<String>,
    /// The world axis that is up in the environment: x, y, z, -x, -y or -z.
    #[arg(long, default_value = "y", value_parser = parse_axis, allow_hyphen_values = true)]
    env_up: [f64; 3],
    /// Turn the environment about its up axis, degrees.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    env_azimuth: f64,
    /// Multiply the environment's radiance.
    #[arg(long, default_value_t = 1.0)]
    env_intensity: f32,
    /// Weight of environment lighting (0: the lights only). Default: 0.6 on isosurfaces
    /// (beside the headlight; 1 with --no-lights), 1 when path tracing.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) env_light: Option<f32>,
    /// Show the environment behind the surfaces.
    #[arg(long)]
    pub(crate) env_background: bool,
    /// Specular environment sampling.
    #[arg(long, value_enum, default_value = "importance")]
    specular: SpecularArg,
    /// Environment samples on the specular lobe per shaded point.
    #[arg(long, default_value_t = 16)]
    specular_samples: u32,
    /// Specular exponent: S (constant) or LO:HI (from LO at weak to HI at strong gradients).
    #[arg(long, default_value = "8:64", value_parser = parse_shininess, allow_hyphen_values = true)]
    shininess: (f32, Option<f32>),
    /// Gradient magnitudes G0:G1 (scalar units per world unit) the LO:HI exponents span
    /// (default: 0 to a quarter of the data range per voxel).
    #[arg(long, value_parser = parse_range, allow_hyphen_values = true)]
    shininess_range: Option<[f64; 2]>,
    /// Schlick Fresnel weighting of specular light with this reflectance at normal incidence.
    #[arg(long)]
    fresnel: Option<f32>,
    /// Ambient occlusion with this many directions per hit.
    #[arg(long)]
    ao: Option<u32>,
    /// Steps per ambient-occlusion ray.
    #[arg(long, default_value_t = 8)]
    ao_steps: u32,
    /// Ambient-occlusion ray length, world units (default: 8 voxels).
    #[arg(long)]
    ao_radius: Option<f64>,
    /// Bisection steps refining each crossing.
    #[arg(long, default_value_t = 8)]
    bisection: u32,
    /// Surface layers kept per pixel (translucent surfaces).
    #[arg(long, default_value_t = 4)]
    layers: u32,
    /// No headlight: environment lighting only.
    #[arg(long)]
    pub(crate) no_lights: bool,
}

/// Default colours of the isosurfaces, in order: bone, skin, then distinct hues.
const ISO_COLORS: [[f32; 3]; 8] = [
    [0.95, 0.92, 0.84],
    [0.92, 0.68, 0.56],
    [0.55, 0.72, 0.95],
    [0.6, 0.88, 0.6],
    [0.95, 0.82, 0.4],
    [0.78, 0.6, 0.92],
    [0.92, 0.5, 0.5],
    [0.55, 0.9, 0.9],
];

type IsoSpec = (f64, Option<f32>, Option<[f32; 3]>);

fn parse_iso(s: &str) -> Result<IsoSpec, String> {
    let mut parts = s.splitn(3, ':');
    let v = parts.next().unwrap_or("").trim();
    let value: f64 = v
        .parse()
        .ok()
        .filter(|x: &f64| x.is_finite())
        .ok_or_else(|| {
            format!("iso-value '{v}' in '{s}' is not a finite number (VALUE[:OPACITY[:R,G,B]])")
        })?;
    let opacity = match parts.next() {
        None => None,
        Some(o) => Some(
            o.trim()
                .parse::<f32>()
                .ok()
                .filter(|a| *a > 0.0 && *a <= 1.0)
                .ok_or_else(|| format!("opacity '{o}' in '{s}' must be a number in (0, 1]"))?,
        ),
    };
    let color = match parts.next() {
        None => None,
        Some(c) => Some(parse_rgb(c).map_err(|e| format!("in '{s}': {e}"))?),
    };
    Ok((value, opacity, color))
}

pub(crate) fn parse_axis(s: &str) -> Result<[f64; 3], String> {
    Ok(match s.trim().to_ascii_lowercase().as_str() {
        "x" | "+x" => [1.0, 0.0, 0.0],
        "y" | "+y" => [0.0, 1.0, 0.0],
        "z" | "+z" => [0.0, 0.0, 1.0],
        "-x" => [-1.0, 0.0, 0.0],
        "-y" => [0.0, -1.0, 0.0],
        "-z" => [0.0, 0.0, -1.0],
        _ => return Err(format!("axis '{s}' must be x, y, z, -x, -y or -z")),
    })
}

fn parse_shininess(s: &str) -> Result<(f32, Option<f32>), String> {
    let num = |p: &str| {
        p.trim()
            .parse::<f32>()
            .ok()
            .filter(|v| v.is_finite() && *v >= 0.0)
            .ok_or_else(|| format!("shininess '{p}' must be a non-negative number"))
    };
    match s.split_once(':') {
        None => Ok((num(s)?, None)),
        Some((a, b)) => Ok((num(a)?, Some(num(b)?))),
    }
}

fn parse_range(s: &str) -> Result<[f64; 2], String> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("range '{s}' must look like LOW:HIGH"))?;
    let num = |p: &str| {
        p.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{p}' in range '{s}' is not a finite number"))
    };
    let (lo, hi) = (num(a)?, num(b)?);
    if lo >= hi {
        return Err(format!("range '{s}': LOW must be below HIGH"));
    }
    Ok([lo, hi])
}

/// The isosurface parameters and environment the flags describe; without --iso, the middle
/// of the data's `range`.
pub(crate) fn iso_setup(
    a: &IsoArgs,
    range: impl FnOnce() -> Result<[f64; 2], CliError>,
) -> Result<(IsoParams, Environment), CliError> {
    let specs: Vec<IsoSpec> = if a.values.is_empty() {
        let [lo, hi] = range()?;
        let mid = 0.5 * (lo + hi);
        eprintln!("ferrovol: no --iso given; using the middle of the data range, {mid}");
        vec![(mid, None, None)]
    } else {
        a.values.clone()
    };
    if specs.len() > ferrovol_core::iso::MAX_ISO_VALUES {
        return Err(CliError::Usage(format!(
            "{} --iso values: at most {}",
            specs.len(),
            ferrovol_core::iso::MAX_ISO_VALUES
        )));
    }
    let values = specs
        .iter()
        .enumerate()
        .map(|(i, &(v, o, c))| IsoValue::new(v, c.unwrap_or(ISO_COLORS[i]), o.unwrap_or(1.0)))
        .collect();
    let shininess = match a.shininess {
        (s, None) => Shininess::Constant(s),
        (lo, Some(hi)) => Shininess::GradientMagnitude {
            range: a.shininess_range,
            exponents: [lo, hi],
        },
    };
    let iso = IsoParams {
        values,
        bisection_steps: a.bisection,
        max_layers: a.layers,
        specular: match a.specular {
            SpecularArg::Cone => SpecularMode::Cone,
            SpecularArg::Importance => SpecularMode::Importance,
        },
        specular_samples: a.specular_samples,
        shininess,
        fresnel: a.fresnel,
        ambient_occlusion: a.ao.map(|n| AmbientOcclusion {
            samples: n,
            steps: a.ao_steps,
            radius: a.ao_radius,
        }),
        environment_light: a.env_light.unwrap_or(0.6),
        background: a.env_background,
        scattering: a.scatter_inside.map(|mode| IsoScattering {
            mode: match mode {
                ScatterInside::Preview => IsoScatterMode::Preview,
                ScatterInside::Traced => IsoScatterMode::Traced,
            },
            samples: a.scatter_samples,
            absorption: a.absorption,
            fresnel: a.fresnel.unwrap_or(IsoScattering::default().fresnel),
        }),
    };
    iso.validate()?;
    Ok((iso, environment_setup(a)?))
}

/// The environment the flags describe (the procedural sky by default).
pub(crate) fn environment_setup(a: &IsoArgs) -> Result<Environment, CliError> {
    let mut env = match (&a.env, &a.env_cube) {
        (Some(e), _) if e != "sky" => {
            ferrovol_io::image::read_environment(std::path::Path::new(e))?
        }
        (_, Some(list)) => {
            let paths: Vec<&std::path::Path> = list.split(',').map(std::path::Path::new).collect();
            let six: &[&std::path::Path; 6] = paths.as_slice().try_into().map_err(|_| {
                CliError::Usage(format!(
                    "--env-cube needs six comma-separated images (+X,-X,+Y,-Y,+Z,-Z), got {}",
                    paths.len()
                ))
            })?;
            ferrovol_io::image::read_environment_cube(six)?
        }
        _ => Environment::default(),
    };
    env.up = glam::DVec3::from_array(a.env_up);
    env.azimuth = a.env_azimuth;
    env.intensity = a.env_intensity;
    env.validate()?;
    Ok(env)
}
