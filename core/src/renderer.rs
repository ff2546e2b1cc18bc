//! The renderer: the one object a user holds. It owns the device context, the resources
//! (volume, tables, output images, environment) and the passes, and runs the passes a frame
//! needs; every public entry point of ferrovol-core's rendering is here.

use crate::error::{Error, Result};
use crate::gpu::interop::{OutputPath, SharedTargets};
use crate::gpu::Context;
use crate::params::{
    BlendMode, BsdfParams, Convergence, CubeImage, Environment, GBuffer, Image, IntermixedVolume,
    IsoParams, MaskKind, PathTraceParams, RenderParams, Residency, Stats, StreamProgress,
    TransferFunction, UnstructuredVolume, UploadOptions, View, VolumeData,
};
use crate::passes::dvr::DvrPass;
use crate::passes::frame::{self, FrameInput, Purpose};
use crate::passes::iso::{self, IsoPass};
use crate::passes::pathtrace::PathTracePass;
use crate::passes::scatter_check;
use crate::passes::unstructured::UnstructuredPass;
use crate::resources::intermix::Intermix;
use crate::resources::levels::LevelDemand;
use crate::resources::targets::DepthSource;
use crate::resources::volume::HostVolume;
use crate::resources::Resources;
use std::sync::Arc;

pub struct Renderer {
    ctx: Context,
    res: Resources,
    dvr: DvrPass,
    /// The passes of the other modes, created on first use.
    iso: Option<Box<IsoPass>>,
    pt: Option<Box<PathTracePass>>,
    unstructured: Option<Box<UnstructuredPass>>,
    iso_params: Option<IsoParams>,
    pt_params: PathTraceParams,
    /// The submissions that end the last frame and the one before it
    /// ([`Renderer::wait_for_previous_frame`]).
    last_frame: Option<wgpu::SubmissionIndex>,
    previous_frame: Option<wgpu::SubmissionIndex>,
}

/// The pass in `slot`, created by `new` on first use.
fn ensure<T>(slot: &mut Option<T>, new: impl FnOnce() -> Result<T>) -> Result<&mut T> {
    if slot.is_none() {
        *slot = Some(new()?);
    }
    Ok(slot.as_mut().expect("created above"))
}

impl Renderer {
    /// Creates the pipelines on a device (picks one with [`Context::new`] if you have none).
    pub fn new(ctx: Context) -> Result<Renderer> {
        let res = Resources::new(&ctx);
        let dvr = DvrPass::new(&ctx, &res.brick_bgl)?;
        Ok(Renderer {
            ctx,
            res,
            dvr,
            iso: None,
            pt: None,
            unstructured: None,
            iso_params: None,
            pt_params: Default::default(),
            last_frame: None,
            previous_frame: None,
        })
    }

    pub fn context(&self) -> &Context {
        &self.ctx
    }

    pub fn stats(&self) -> Stats {
        self.res.stats
    }

    /// Number of bricks the current volume is split into (0 without a volume).
    pub fn brick_count(&self) -> usize {
        self.res.volume.as_ref().map_or(0, |v| v.grid.len())
    }

    /// The texture format the current volume is stored in.
    pub fn volume_format(&self) -> Option<wgpu::TextureFormat> {
        self.res.volume.as_ref().map(|v| v.layout.format)
    }

    /// Uploads a volume (replacing any previous one).
    pub fn set_volume(&mut self, v: &VolumeData) -> Result<()> {
        self.set_volume_with(v, UploadOptions::default())
    }

    /// Uploads a volume with `opts`. A volume too large for one texture is bricked and
    /// keeps a copy of `v` to read bricks from as frames need them
    /// ([`Renderer::set_shared_volume`] shares it instead).
    pub fn set_volume_with(&mut self, v: &VolumeData, opts: UploadOptions) -> Result<()> {
        self.res
            .set_volume(&self.ctx, HostVolume::Borrowed(v), opts)
    }

    /// [`Renderer::set_volume_with`] for data the caller shares: a bricked volume reads its
    /// bricks from `v` without a copy.
    pub fn set_shared_volume(&mut self, v: Arc<VolumeData>, opts: UploadOptions) -> Result<()> {
        self.res.set_volume(&self.ctx, HostVolume::Shared(v), opts)
    }

    /// Uploads an unstructured volume (replacing any previous volume, image or mesh): cells
    /// split into tetrahedra ([`crate::tetrahedralize`]), their neighbours and a hierarchy
    /// over the boundary; a triangle shared by more than two tetrahedra is an error naming
    /// their cells. Drawn from its first scalar component. [`Renderer::render`] and [`Renderer::render_image`] then draw
    /// it with the same view, parameters and transfer function as an image volume;
    /// [`Renderer::set_volume`] goes back to an image. The tetrahedra (16 bytes each, and 16
    /// of neighbours) may take two of the device's storage-buffer bindings; a mesh past them,
    /// or whose points exceed one, is refused with the sizes (about 38 bytes per
    /// tetrahedron in all).
    pub fn set_unstructured(&mut self, v: &UnstructuredVolume) -> Result<()> {
        self.res.set_mesh(&self.ctx, v)
    }

    /// Blanks points of the current volume's grid (VTK's ghost arrays and vtkUniformGrid
    /// blanking): `mask` holds one byte per point, x fastest, non-zero where the point is
    /// hidden. Ray casting skips a sample when the point nearest to it or the points around
    /// it along an axis are hidden, as vtkGPUVolumeRayCastMapper does; isosurfaces and path
    /// tracing do not read the mask. `None` clears it; a new volume clears it too. A volume
    /// of one brick only.
    pub fn set_blanking(&mut self, mask: Option<&[u8]>) -> Result<()> {
        self.res.set_blanking(&self.ctx, mask)
    }

    /// Masks the current volume (VTK's MaskInput with MaskType): `values` holds one byte per
    /// point of the volume's grid, x fastest, read at the point nearest to each sample, as
    /// `kind` says ([`MaskKind`]): ray casting, path tracing and (binary masks) the
    /// isosurfaces' first hits read it. `None` clears it; a new volume clears it too.
    pub fn set_mask(&mut self, mask: Option<(&[u8], MaskKind)>) -> Result<()> {
        self.res.set_mask(&self.ctx, mask)
    }

    /// Sets the volumes drawn with the main one, intermixed per sample (VTK's vtkMultiVolume:
    /// the main volume is port 0, `volumes[i]` port i + 1). Ray casting (the composite blend
    /// mode) marches the world box holding them all at the main volume's sample distance,
    /// and at each sample composites the main volume and then each intermixed volume that
    /// holds the sample, each classified by its own transfer function (opacity corrected for
    /// the step by its own unit distance) and read with its own interpolation, and shaded,
    /// when shading is on, by its own gradient with the main volume's lights and material.
    /// The path tracer adds their media: at a point the extinctions add up, and a collision
    /// scatters with the colour of the medium it met, drawn in proportion to the media's
    /// extinctions; intermixed volumes are read without their gradients (they scatter as the
    /// main volume's medium where its gradient is zero). At most
    /// [`MAX_INTERMIXED_VOLUMES`](crate::MAX_INTERMIXED_VOLUMES); an empty slice clears
    /// them. Data shared with the previous call (the same `Arc`s) is not uploaded again.
    pub fn set_intermixed_volumes(&mut self, volumes: &[IntermixedVolume]) -> Result<()> {
        self.res.intermix = Intermix::new(&self.ctx, self.res.intermix.as_ref(), volumes)?;
        self.res.intermix_generation += 1;
        Ok(())
    }

    /// The intermixed volumes set last.
    pub fn intermixed_volumes(&self) -> &[IntermixedVolume] {
        self.res.intermix.as_ref().map_or(&[], |m| &m.volumes)
    }

    /// Calls `progress` after each pass of a streamed frame (`None`: no calls).
    pub fn set_progress(&mut self, progress: Option<StreamProgress>) {
        self.res.progress = progress;
    }

    /// How much of the volume is on the device (zeros without a volume), and the level of
    /// detail the last frame drew.
    pub fn residency(&self) -> Residency {
        let mut r = self
            .res
            .volume
            .as_ref()
            .map_or(Residency::default(), |v| v.residency());
        let (dims, level_pool) = self.res.level_residency();
        r.level = self.res.drawn_level;
        r.level_dims = dims;
        r.pool_bytes += level_pool;
        r
    }

    /// Sets the transfer function; its tables are (re)built at the next frame if it changed.
    pub fn set_transfer_function(&mut self, tf: &TransferFunction) -> Result<()> {
        let comps = self
            .res
            .volume
            .as_ref()
            .map_or(tf.components.len() as u32, |v| v.components);
        tf.validate(comps)?;
        self.res.tf = Some(tf.clone());
        Ok(())
    }

    /// The world distance between samples these parameters give for the current volume.
    pub fn sample_distance(&self, params: &RenderParams) -> Result<f64> {
        self.res.sample_distance(params)
    }

    /// Fraction of occupancy blocks the last frame's transfer function left non-empty.
    pub fn occupied_fraction(&self) -> Option<f64> {
        self.res.occupancy.as_ref().map(|o| o.fraction)
    }

    /// Sets the isosurfaces and their shading for frames with
    /// [`BlendMode::Isosurface`].
    pub fn set_isosurface(&mut self, iso: &IsoParams) -> Result<()> {
        iso.validate()?;
        self.iso_params = Some(iso.clone());
        Ok(())
    }

    /// The isosurface parameters set last.
    pub fn isosurface(&self) -> Option<&IsoParams> {
        self.iso_params.as_ref()
    }

    /// Builds the environment's GPU maps (environment cube with mips, irradiance cube) now;
    /// isosurface and path-traced frames use them until the next call. Without a call, the
    /// first such frame builds the default procedural sky.
    pub fn set_environment(&mut self, env: &Environment) -> Result<()> {
        self.res.set_environment(&self.ctx, env)
    }

    /// The irradiance cube of the current environment (π-normalised: E/π), for inspection
    /// and tests.
    pub fn read_irradiance(&self) -> Result<CubeImage> {
        self.res.read_irradiance(&self.ctx)
    }

    /// Mip level `level` of the current environment cube.
    pub fn read_environment(&self, level: u32) -> Result<CubeImage> {
        self.res.read_environment(&self.ctx, level)
    }

    /// Waits for the last isosurface frame and copies its G-buffer to the CPU.
    pub fn read_gbuffer(&self) -> Result<GBuffer> {
        match &self.iso {
            Some(iso) => iso.read_gbuffer(&self.ctx, &self.res),
            None => Err(Error::InvalidParameter(
                "no isosurface frame has been rendered yet".into(),
            )),
        }
    }

    /// Sets how frames with [`BlendMode::PathTrace`] sample
    /// (a change other than of the paths per frame starts the accumulation over).
    pub fn set_path_tracing(&mut self, p: &PathTraceParams) -> Result<()> {
        p.validate()?;
        self.pt_params = *p;
        Ok(())
    }

    /// The path tracing settings set last (the defaults before any call).
    pub fn path_tracing(&self) -> &PathTraceParams {
        &self.pt_params
    }

    /// Paths per pixel the last path-traced frame shows (0 before the first).
    pub fn accumulated_samples(&self) -> u32 {
        self.pt.as_ref().map_or(0, |p| p.samples())
    }

    /// How far the path tracer's accumulation has come, with its estimated error (waits for
    /// the last frame and reads the accumulation back: a cost to pay on demand, not every
    /// frame). Zeros before the first path-traced frame.
    pub fn convergence(&self) -> Result<Convergence> {
        match &self.pt {
            Some(p) => p.convergence(&self.ctx),
            None => Ok(Convergence::default()),
        }
    }

    /// Starts the accumulation over at the next path-traced frame.
    pub fn reset_accumulation(&mut self) {
        if let Some(p) = self.pt.as_mut() {
            p.reset_accumulation();
        }
    }

    /// Waits for the last path-traced frame and returns its per-pixel mean over the
    /// accumulated paths, rows top to bottom: radiance (rgb, linear, not clipped) and the
    /// fraction of paths that met the medium (a; 1 everywhere with the background on).
    pub fn read_accumulation(&self) -> Result<Vec<[f32; 4]>> {
        match &self.pt {
            Some(p) => p.read_accumulation(&self.ctx),
            None => Err(Error::InvalidParameter(
                "no path-traced frame has been rendered yet".into(),
            )),
        }
    }

    /// Draws `n` Henyey–Greenstein scattering directions with anisotropy `g` by the path
    /// tracer's own sampling code (shaders/lib/phase.wgsl) and returns the cosine of each
    /// to the propagation direction: for checking the sampler against the density.
    pub fn sample_phase_cosines(&self, g: f32, n: u32, seed: u32) -> Result<Vec<f32>> {
        scatter_check::sample_phase_cosines(&self.ctx, g, n, seed)
    }

    /// Checks the path tracer's BSDF (shaders/lib/bsdf.wgsl, colour 1) at a surface with
    /// gradient direction `normal` for a path arriving along `dir` (both unit vectors):
    /// per sample, [value / density of a direction drawn by its sampler, 4π × value and 4π ×
    /// density of a uniformly drawn direction]. The means of the first two estimate the
    /// albedo (≤ 1 when energy is conserved; equal when sampler and density agree), the
    /// mean of the third is 1 when the density is normalised.
    pub fn sample_bsdf(
        &self,
        bsdf: &BsdfParams,
        normal: [f32; 3],
        dir: [f32; 3],
        n: u32,
        seed: u32,
    ) -> Result<Vec<[f32; 3]>> {
        scatter_check::sample_bsdf(&self.ctx, bsdf, [normal, dir], [n, seed])
    }

    /// Renders one frame and returns once it is submitted; read it with [`Renderer::read_image`]
    /// or, with [`OutputPath::Shared`], wait with [`Renderer::finish`] and sample the shared
    /// images. `depth` (window depth per pixel, rows top to bottom) terminates rays at opaque
    /// geometry.
    pub fn render(
        &mut self,
        view: &View,
        params: &RenderParams,
        depth: Option<&[f32]>,
    ) -> Result<()> {
        let source = match depth {
            Some(d) => DepthSource::Cpu(d),
            None => DepthSource::None,
        };
        self.render_from(view, params, source, Purpose::Draw)
    }

    /// Prepares what a frame with `view` and `params` needs, without drawing it: the pass of
    /// its blend mode, the transfer function's tables, the occupancy and environment maps,
    /// the bricks it reads, the output images of the view's size and the pipelines of the
    /// variant it selects, compiled. A host calls it at set-up, after
    /// [`Renderer::set_volume`] and [`Renderer::set_transfer_function`], so that its first
    /// [`Renderer::render`] with those settings does not pay for them. Settings a frame
    /// would refuse are refused here, with the same error.
    pub fn prepare(&mut self, view: &View, params: &RenderParams) -> Result<()> {
        self.render_from(view, params, DepthSource::None, Purpose::Prepare)
    }

    /// Like [`Renderer::render`] with a depth input, but the depth is what the host wrote into
    /// the shared depth-input image ([`SharedTargets::depth_in`], window depth, rows top to
    /// bottom) instead of an upload. Needs [`OutputPath::Shared`] and output images of the
    /// view's size already allocated ([`Renderer::prepare_targets`] or an earlier frame); the
    /// host must have finished writing (`glFinish`) before this call.
    pub fn render_with_shared_depth(&mut self, view: &View, params: &RenderParams) -> Result<()> {
        match &self.res.targets {
            Some(t)
                if t.path() == OutputPath::Shared
                    && self.res.output_path == OutputPath::Shared
                    && t.width == view.width
                    && t.height == view.height => {}
            Some(t)
                if t.path() == OutputPath::Shared && self.res.output_path == OutputPath::Shared =>
            {
                return Err(Error::InvalidParameter(format!(
                    "the shared depth input is {}x{}, the view {}x{}: call \
                     Renderer::prepare_targets({}, {}), import the new images and write the \
                     depth into the new depth input first",
                    t.width, t.height, view.width, view.height, view.width, view.height
                )))
            }
            _ => {
                return Err(Error::InvalidParameter(
                    "no shared depth input: switch to OutputPath::Shared and call \
                     Renderer::prepare_targets, import SharedTargets::depth_in and write the depth \
                     into it first"
                        .into(),
                ))
            }
        }
        self.render_from(view, params, DepthSource::Shared, Purpose::Draw)
    }

    /// Like [`Renderer::render`], but each pixel's ray samples only between two window depths
    /// (`near` and `far`, 0 near … 1 far, rows top to bottom, half-open: nothing where
    /// near ≥ far), on the lattice the whole ray would use, so that segments which meet
    /// share no sample. A host peeling translucent geometry (VTK's dual depth peeling)
    /// renders the volume between its layers this way ([`crate::Quadrature::Midpoint`]: the range
    /// is the path itself, its steps ending exactly at both ends). Ray casting only: the
    /// isosurface, slice and path-tracing blend modes and volumetric shadows are refused.
    pub fn render_between(
        &mut self,
        view: &View,
        params: &RenderParams,
        near: &[f32],
        far: &[f32],
    ) -> Result<()> {
        let refused = match params.blend {
            BlendMode::Isosurface | BlendMode::Slice | BlendMode::PathTrace => {
                Some(format!("the {:?} blend mode", params.blend))
            }
            _ if frame::casts_shadows(view, params) => Some("volumetric shadows".to_string()),
            _ => None,
        };
        if let Some(what) = refused {
            return Err(Error::Unsupported(format!(
                "rays limited to a depth range are ray cast: {what} draws whole rays (render \
                 without a depth range, or use a ray-casting blend mode)"
            )));
        }
        self.render_from(view, params, DepthSource::Range(near, far), Purpose::Draw)
    }

    fn render_from(
        &mut self,
        view: &View,
        params: &RenderParams,
        depth: DepthSource<'_>,
        purpose: Purpose,
    ) -> Result<()> {
        self.ctx.check_lost("rendering")?;
        let (ctx, res) = (&self.ctx, &mut self.res);
        let input = |res| FrameInput {
            ctx,
            res,
            view,
            params,
            depth,
            purpose,
        };
        if res.mesh.is_some() {
            let done = if params.blend == BlendMode::PathTrace {
                let brick_bgl = &res.brick_bgl;
                let pass = ensure(&mut self.pt, || {
                    Ok(Box::new(PathTracePass::new(ctx, brick_bgl)?))
                })?;
                pass.render(input(res), &self.pt_params)
            } else if params.blend == BlendMode::Isosurface {
                let brick_bgl = &res.brick_bgl;
                let pass = ensure(&mut self.iso, || {
                    Ok(Box::new(IsoPass::new(ctx, brick_bgl)?))
                })?;
                pass.render_mesh(input(res), self.iso_params.as_ref())
            } else {
                let pass = ensure(&mut self.unstructured, || {
                    Ok(Box::new(UnstructuredPass::new(ctx)?))
                })?;
                pass.render(input(res))
            };
            if done.is_ok() && purpose == Purpose::Draw {
                self.previous_frame =
                    std::mem::replace(&mut self.last_frame, ctx.last_submission());
            }
            return done;
        }
        // Rays that go anywhere cannot stream: past the budget such a frame draws a coarser
        // level of the volume.
        let anywhere = match params.blend {
            BlendMode::PathTrace => Some((LevelDemand::Visible, "a path-traced frame")),
            BlendMode::Isosurface => match self.iso_params.as_ref() {
                Some(iso) if res.volume.is_some() => iso::level_demand(iso, res)?
                    .map(|d| (d, "ambient occlusion or scattering between isosurfaces")),
                _ => None,
            },
            _ if frame::casts_shadows(view, params) => {
                Some((LevelDemand::Visible, "a frame with volumetric shadows"))
            }
            _ => None,
        };
        // (preview frames past the budget draw coarser bricks where fine ones are missing,
        // resources/lod.rs)
        match &anywhere {
            Some((demand, what)) if res.intermix.is_none() => {
                res.enter_level(ctx, params, demand, what)?
            }
            _ => res.release_level(),
        }
        if res.intermix.is_some()
            && !matches!(params.blend, BlendMode::Composite | BlendMode::PathTrace)
        {
            return Err(Error::Unsupported(format!(
                "intermixed volumes are drawn in the composite blend mode and path traced, \
                 not in {:?}: clear them (set_intermixed_volumes with none) or use one of \
                 those modes",
                params.blend
            )));
        }
        let done = match params.blend {
            BlendMode::Isosurface => {
                let brick_bgl = &res.brick_bgl;
                let pass = ensure(&mut self.iso, || {
                    Ok(Box::new(IsoPass::new(ctx, brick_bgl)?))
                })?;
                pass.render(input(&mut *res), self.iso_params.as_ref())
            }
            BlendMode::PathTrace => {
                let brick_bgl = &res.brick_bgl;
                let pass = ensure(&mut self.pt, || {
                    Ok(Box::new(PathTracePass::new(ctx, brick_bgl)?))
                })?;
                pass.render(input(&mut *res), &self.pt_params)
            }
            _ => self.dvr.render(input(&mut *res)),
        };
        res.leave_level();
        if done.is_ok() && purpose == Purpose::Draw {
            self.previous_frame = std::mem::replace(&mut self.last_frame, ctx.last_submission());
        }
        done
    }

    /// The output texture (premultiplied RGBA8) of the last frame.
    pub fn output_texture(&self) -> Option<&wgpu::Texture> {
        self.res.targets.as_ref().map(|t| &t.color)
    }

    /// Chooses where frames go. [`OutputPath::Shared`] needs a device that can export memory
    /// ([`Context::external_memory_support`]); without one this returns that error
    /// ([`Error::Unsupported`], saying why) and the renderer stays on the path it had. The
    /// output images are reallocated at the next frame or [`Renderer::prepare_targets`].
    pub fn set_output_path(&mut self, path: OutputPath) -> Result<()> {
        if path == OutputPath::Shared {
            self.ctx.external_memory_support()?;
        }
        self.res.output_path = path;
        Ok(())
    }

    /// [`Renderer::set_output_path`] with [`OutputPath::Shared`] (`true`) or
    /// [`OutputPath::Readback`] (`false`).
    pub fn set_output_sharing(&mut self, on: bool) -> Result<()> {
        self.set_output_path(if on {
            OutputPath::Shared
        } else {
            OutputPath::Readback
        })
    }

    /// The path chosen with [`Renderer::set_output_path`] (the default is
    /// [`OutputPath::Readback`]).
    pub fn output_path(&self) -> OutputPath {
        self.res.output_path
    }

    /// Allocates the output images for frames of `width × height` on the current path now
    /// rather than at the next frame, so the host can import them (and write the depth input)
    /// before rendering. Does nothing when they already fit.
    pub fn prepare_targets(&mut self, width: u32, height: u32) -> Result<()> {
        self.res.ensure_targets(&self.ctx, width, height)
    }

    /// Counts allocations of the output images: it changes exactly when they are replaced
    /// (a new size, a path switch), i.e. when a host must import them again. 0 before the
    /// first allocation.
    pub fn output_generation(&self) -> u64 {
        self.res.targets.as_ref().map_or(0, |t| t.generation)
    }

    /// Exports the output images: new file descriptors (the caller owns them) with what
    /// OpenGL needs to import them; see [`crate::interop`] for the protocol. Needs
    /// [`OutputPath::Shared`] and images allocated on it (a frame rendered or
    /// [`Renderer::prepare_targets`] called after switching).
    pub fn shared_targets(&self) -> Result<SharedTargets> {
        self.res.shared_targets(&self.ctx)
    }

    /// Blocks until the GPU has finished every frame submitted so far. With
    /// [`OutputPath::Shared`] this is the synchronisation with the host: call it after
    /// [`Renderer::render`] and before the host samples the shared images (no semaphores are
    /// shared; Mesa's llvmpipe has no `GL_EXT_semaphore_fd`).
    pub fn finish(&self) -> Result<()> {
        self.ctx.wait_idle()
    }

    /// Blocks until every frame but the last has finished on the device: two frames in
    /// flight. A host that renders frame after frame calls it before recording the next, so
    /// that the device draws one frame while the host prepares the next, instead of idling
    /// while the host waits ([`Renderer::finish`]) and then records.
    pub fn wait_for_previous_frame(&mut self) -> Result<()> {
        match self.previous_frame.take() {
            Some(previous) => self
                .ctx
                .wait_for(Some(previous), "waiting for the previous frame"),
            None => Ok(()),
        }
    }

    /// Waits for the last frame and copies its colour and depth to the CPU.
    pub fn read_image(&self) -> Result<Image> {
        self.res.read_image(&self.ctx)
    }

    /// Renders and reads back in one call.
    pub fn render_image(&mut self, view: &View, params: &RenderParams) -> Result<Image> {
        self.render(view, params, None)?;
        self.read_image()
    }
}
