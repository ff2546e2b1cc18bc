//! The environment on the device: the environment cube with its mips and the irradiance
//! cube, built from an [`Environment`] by the passes of shaders/environment.wgsl.

use super::Resources;
use crate::error::{Error, Result};
use crate::gpu::binding::{
    bind, bind_view, buffer_entry, sampler_entry, storage_texture_entry, texture_entry,
};
use crate::gpu::buffers::uniform_buffer;
use crate::gpu::pipeline::{compute_pipeline, encode_single_group, pipeline_layout};
use crate::gpu::readback::read_texture_layer;
use crate::gpu::texture::texture_2d;
use crate::gpu::uniforms::{EnvUniforms, ENV_EQUIRECT, ENV_SKY};
use crate::gpu::Context;
use crate::params::environment::{CubeImage, Environment, EnvironmentSource, IRRADIANCE_SIZE};
use glam::DMat3;
use wgpu::util::DeviceExt;

/// The environment passes (shaders/environment.wgsl): created on first use.
pub(crate) struct EnvPipelines {
    build_bgl: wgpu::BindGroupLayout,
    downsample_bgl: wgpu::BindGroupLayout,
    irradiance_bgl: wgpu::BindGroupLayout,
    build: wgpu::ComputePipeline,
    downsample: wgpu::ComputePipeline,
    irradiance: wgpu::ComputePipeline,
    equirect_sampler: wgpu::Sampler,
    pub cube_sampler: wgpu::Sampler,
}

/// The maps of one environment on the GPU.
pub(crate) struct GpuEnvironment {
    pub cube: wgpu::Texture,
    pub cube_view: wgpu::TextureView,
    pub irradiance: wgpu::Texture,
    pub irradiance_view: wgpu::TextureView,
    pub size: u32,
    pub mips: u32,
    /// World → environment directions.
    pub rotation: DMat3,
}

const ENV_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

impl EnvPipelines {
    /// environment.wgsl's entry points (build, downsample, irradiance), each with its bind
    /// group.
    pub fn layouts() -> [(&'static str, Vec<wgpu::BindGroupLayoutEntry>); 3] {
        use wgpu::TextureViewDimension as V;
        let with = |more: Vec<wgpu::BindGroupLayoutEntry>| {
            let mut entries = vec![
                buffer_entry(0, wgpu::BufferBindingType::Uniform),
                storage_texture_entry(3, ENV_FORMAT, V::D2Array),
            ];
            entries.extend(more);
            entries
        };
        [
            (
                "build",
                with(vec![texture_entry(1, true, V::D2), sampler_entry(2)]),
            ),
            ("downsample", with(vec![texture_entry(4, true, V::D2Array)])),
            (
                "irradiance",
                with(vec![texture_entry(5, true, V::Cube), sampler_entry(6)]),
            ),
        ]
    }

    pub fn new(ctx: &Context) -> Result<EnvPipelines> {
        let d = &ctx.device;
        let [build_bgl, downsample_bgl, irradiance_bgl] =
            Self::layouts().map(|(entry, entries)| {
                d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some(&format!("environment {entry}")),
                    entries: &entries,
                })
            });
        let pipeline = |entry: &'static str, layout: &wgpu::BindGroupLayout| {
            let pl = pipeline_layout(ctx, entry, &[layout]);
            compute_pipeline(
                ctx,
                &format!("environment {entry}"),
                &pl,
                "environment.wgsl",
                entry,
                &[],
            )
        };
        let build = pipeline("build", &build_bgl)?;
        let downsample = pipeline("downsample", &downsample_bgl)?;
        let irradiance = pipeline("irradiance", &irradiance_bgl)?;
        let equirect_sampler = d.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("equirect"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let cube_sampler = d.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("environment cube"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        Ok(EnvPipelines {
            build_bgl,
            downsample_bgl,
            irradiance_bgl,
            build,
            downsample,
            irradiance,
            equirect_sampler,
            cube_sampler,
        })
    }
}

fn to_half(c: [f32; 3], scale: f32) -> [half::f16; 4] {
    // rgba16float's largest finite value; brighter texels are clamped, not made infinite
    let h = |v: f32| half::f16::from_f32((v * scale).clamp(0.0, 65504.0));
    [h(c[0]), h(c[1]), h(c[2]), half::f16::ONE]
}

fn cube_texture(ctx: &Context, label: &str, size: u32, mips: u32) -> wgpu::Texture {
    ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 6,
        },
        mip_level_count: mips,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: ENV_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

fn level_view(
    tex: &wgpu::Texture,
    level: u32,
    dim: wgpu::TextureViewDimension,
) -> wgpu::TextureView {
    tex.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(dim),
        base_mip_level: level,
        mip_level_count: Some(1),
        ..Default::default()
    })
}

impl GpuEnvironment {
    /// Builds the environment cube, its mip chain and the irradiance cube, and waits for them.
    pub fn build(ctx: &Context, p: &EnvPipelines, env: &Environment) -> Result<GpuEnvironment> {
        env.validate()?;
        let d = &ctx.device;
        let q = &ctx.queue;
        let size = env.cube_size();
        let mips = 32 - size.leading_zeros();
        let max2d = ctx.info.limits.max_texture_dimension_2d;
        if size > max2d {
            return Err(Error::Unsupported(format!(
                "an environment cube of {size}² per face exceeds this device's texture limit \
                 {max2d}; set Environment::resolution lower"
            )));
        }
        let mut u = EnvUniforms {
            scale: [env.intensity, 0.0, 0.0, 0.0],
            ..Default::default()
        };
        let (cube, irradiance) = ctx.checked("building the environment maps", || {
            let cube = cube_texture(ctx, "environment cube", size, mips);
            let irradiance = cube_texture(ctx, "irradiance cube", IRRADIANCE_SIZE, 1);
            (cube, irradiance)
        })?;
        let uniform = |u: &EnvUniforms| {
            let b = uniform_buffer(
                ctx,
                "environment uniforms",
                std::mem::size_of::<EnvUniforms>() as u64,
            );
            q.write_buffer(&b, 0, bytemuck::bytes_of(u));
            b
        };
        let groups = |n: u32| n.div_ceil(8);
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("environment"),
        });
        // Level 0 from the source.
        let mut keep = Vec::new();
        match &env.source {
            EnvironmentSource::Cube { size, faces } => {
                for (f, texels) in faces.iter().enumerate() {
                    let data: Vec<[half::f16; 4]> =
                        texels.iter().map(|&c| to_half(c, env.intensity)).collect();
                    q.write_texture(
                        wgpu::TexelCopyTextureInfo {
                            texture: &cube,
                            mip_level: 0,
                            origin: wgpu::Origin3d {
                                x: 0,
                                y: 0,
                                z: f as u32,
                            },
                            aspect: wgpu::TextureAspect::All,
                        },
                        bytemuck::cast_slice(&data),
                        wgpu::TexelCopyBufferLayout {
                            offset: 0,
                            bytes_per_row: Some(8 * size),
                            rows_per_image: Some(*size),
                        },
                        wgpu::Extent3d {
                            width: *size,
                            height: *size,
                            depth_or_array_layers: 1,
                        },
                    );
                }
            }
            src => {
                let (source, width, height, texels): (u32, u32, u32, Vec<[half::f16; 4]>) =
                    match src {
                        EnvironmentSource::Sky(s) => {
                            let sun = s.sun_direction.normalize();
                            let v4 = |c: [f32; 3], w: f32| [c[0], c[1], c[2], w];
                            u.zenith = v4(s.zenith, 0.0);
                            u.horizon = v4(s.horizon, 0.0);
                            u.ground = v4(s.ground, 0.0);
                            u.sun = [
                                sun.x as f32,
                                sun.y as f32,
                                sun.z as f32,
                                (s.sun_radius_deg as f64).to_radians().cos() as f32,
                            ];
                            u.sun_color = v4(s.sun_color, s.sun_halo);
                            (ENV_SKY, 1, 1, vec![[half::f16::ZERO; 4]])
                        }
                        EnvironmentSource::Equirect {
                            width,
                            height,
                            texels,
                        } => {
                            if *width > max2d {
                                return Err(Error::Unsupported(format!(
                                    "an equirectangular map {width} texels wide exceeds this \
                                     device's texture limit {max2d}; scale it down"
                                )));
                            }
                            let data = texels.iter().map(|&c| to_half(c, 1.0)).collect();
                            (ENV_EQUIRECT, *width, *height, data)
                        }
                        EnvironmentSource::Cube { .. } => unreachable!("handled above"),
                    };
                let src_tex = d.create_texture_with_data(
                    q,
                    &texture_2d(
                        "equirectangular source",
                        [width, height],
                        ENV_FORMAT,
                        wgpu::TextureUsages::TEXTURE_BINDING,
                    ),
                    wgpu::util::TextureDataOrder::LayerMajor,
                    bytemuck::cast_slice(&texels),
                );
                u.params = [source, size, 0, 0];
                let ub = uniform(&u);
                let src_view = src_tex.create_view(&Default::default());
                let dst = level_view(&cube, 0, wgpu::TextureViewDimension::D2Array);
                encode_single_group(
                    ctx,
                    &mut enc,
                    "environment build",
                    (&p.build_bgl, &p.build),
                    &[
                        bind(0, ub.as_entire_binding()),
                        bind_view(1, &src_view),
                        bind(2, wgpu::BindingResource::Sampler(&p.equirect_sampler)),
                        bind_view(3, &dst),
                    ],
                    [groups(size), groups(size), 6],
                );
                keep.push(src_tex);
            }
        }
        // The mip chain, 2×2 box filtered.
        for level in 1..mips {
            let s = (size >> level).max(1);
            u.params = [0, s, 0, 0];
            let ub = uniform(&u);
            let src = level_view(&cube, level - 1, wgpu::TextureViewDimension::D2Array);
            let dst = level_view(&cube, level, wgpu::TextureViewDimension::D2Array);
            encode_single_group(
                ctx,
                &mut enc,
                "environment downsample",
                (&p.downsample_bgl, &p.downsample),
                &[
                    bind(0, ub.as_entire_binding()),
                    bind_view(3, &dst),
                    bind_view(4, &src),
                ],
                [groups(s), groups(s), 6],
            );
        }
        // The irradiance cube.
        let cube_view = cube.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::Cube),
            ..Default::default()
        });
        u.scale[1] = texel_solid_angle(size) as f32;
        u.scale[2] = (mips - 1) as f32;
        u.params = [0, IRRADIANCE_SIZE, env.irradiance_samples, 0];
        let ub = uniform(&u);
        let dst = level_view(&irradiance, 0, wgpu::TextureViewDimension::D2Array);
        encode_single_group(
            ctx,
            &mut enc,
            "environment irradiance",
            (&p.irradiance_bgl, &p.irradiance),
            &[
                bind(0, ub.as_entire_binding()),
                bind_view(3, &dst),
                bind_view(5, &cube_view),
                bind(6, wgpu::BindingResource::Sampler(&p.cube_sampler)),
            ],
            [groups(IRRADIANCE_SIZE), groups(IRRADIANCE_SIZE), 6],
        );
        ctx.checked("computing the environment maps", || {
            ctx.submit([enc.finish()]);
        })?;
        ctx.wait_idle()?;
        drop(keep);
        let irradiance_view = irradiance.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::Cube),
            ..Default::default()
        });
        Ok(GpuEnvironment {
            cube,
            cube_view,
            irradiance,
            irradiance_view,
            size,
            mips,
            rotation: env.rotation(),
        })
    }
}

/// Solid angle of one texel of a cube with `size²` texels per face, averaged over the cube.
pub(crate) fn texel_solid_angle(size: u32) -> f64 {
    4.0 * std::f64::consts::PI / (6.0 * size as f64 * size as f64)
}

/// The environment's GPU state: its build passes (created on first use), the maps of the
/// environment set last, and a count of environments set.
#[derive(Default)]
pub(crate) struct EnvironmentState {
    pipelines: Option<EnvPipelines>,
    pub current: Option<GpuEnvironment>,
    /// Counts set_environment calls (path tracing restarts its accumulation on a change).
    pub generation: u64,
}

fn read_cube(ctx: &Context, tex: &wgpu::Texture, mip: u32) -> Result<CubeImage> {
    let size = (tex.width() >> mip).max(1);
    let mut faces = Vec::with_capacity(6);
    for f in 0..6 {
        let bytes = read_texture_layer(ctx, tex, mip, f, 8)?;
        let halves: &[half::f16] = bytemuck::cast_slice(&bytes);
        faces.push(
            halves
                .chunks(4)
                .map(|c| [c[0].to_f32(), c[1].to_f32(), c[2].to_f32(), c[3].to_f32()])
                .collect(),
        );
    }
    Ok(CubeImage { size, faces })
}

impl Resources {
    /// Builds the environment's GPU maps now (see [`crate::Renderer::set_environment`]).
    pub fn set_environment(&mut self, ctx: &Context, env: &Environment) -> Result<()> {
        env.validate()?;
        let state = &mut self.environment;
        if state.pipelines.is_none() {
            state.pipelines = Some(EnvPipelines::new(ctx)?);
        }
        let pipelines = state.pipelines.as_ref().expect("created above");
        state.current = None;
        state.current = Some(GpuEnvironment::build(ctx, pipelines, env)?);
        state.generation += 1;
        Ok(())
    }

    /// Builds the default environment (the procedural sky) unless one is set: isosurfaces
    /// and path tracing are lit by it.
    pub fn ensure_environment(&mut self, ctx: &Context) -> Result<()> {
        if self.environment.current.is_none() {
            self.set_environment(ctx, &Environment::default())?;
        }
        Ok(())
    }

    /// The sampler the passes read the environment cubes with.
    pub fn cube_sampler(&self) -> Result<&wgpu::Sampler> {
        self.environment
            .pipelines
            .as_ref()
            .map(|p| &p.cube_sampler)
            .ok_or_else(no_environment)
    }

    pub fn current_environment(&self) -> Result<&GpuEnvironment> {
        self.environment.current.as_ref().ok_or_else(no_environment)
    }

    /// The irradiance cube of the current environment.
    pub fn read_irradiance(&self, ctx: &Context) -> Result<CubeImage> {
        let e = self.current_environment()?;
        read_cube(ctx, &e.irradiance, 0)
    }

    /// Mip level `level` of the current environment cube.
    pub fn read_environment(&self, ctx: &Context, level: u32) -> Result<CubeImage> {
        let e = self.current_environment()?;
        if level >= e.mips {
            return Err(Error::InvalidParameter(format!(
                "environment cube level {level}: it has levels 0 to {}",
                e.mips - 1
            )));
        }
        read_cube(ctx, &e.cube, level)
    }
}

fn no_environment() -> Error {
    Error::InvalidParameter(
        "no environment yet: call Renderer::set_environment or render an isosurface frame \
         first"
            .into(),
    )
}
