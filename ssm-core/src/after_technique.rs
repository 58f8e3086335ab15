//! The framework's passes after a technique's, for each light: the receivers past the light
//! frame's widest angle ([`beyond_frame`](crate::beyond_frame), for techniques that see the light
//! through that frame), then the surface's own share of the light
//! ([`own_surface`](crate::own_surface), for techniques that sample it from its centre). Each is
//! timed and counted as one of the technique's passes, named after it.

use crate::beyond_frame::{BEYOND_FRAME_DIAGNOSTIC, BeyondFrame};
use crate::context::GpuContext;
use crate::error::Result;
use crate::frame::Frame;
use crate::own_surface::OwnSurfaceShare;
use crate::technique::{ShadowTechnique, TechniqueInfo, TechniqueSetup};
use crate::work::ShaderWork;

/// A technique followed by the framework's passes it gets.
struct WithFrameworkPasses {
    technique: Box<dyn ShadowTechnique>,
    beyond_frame: Option<BeyondFrame>,
    own_surface_share: Option<OwnSurfaceShare>,
}

impl ShadowTechnique for WithFrameworkPasses {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        self.technique.render(frame, light, output)?;
        // Past the frame first: the share then scales what the faces answered, as it scales the
        // technique's value elsewhere.
        if let Some(beyond_frame) = &self.beyond_frame {
            beyond_frame.encode(frame, light)?;
        }
        if let Some(share) = &self.own_surface_share {
            share.encode(frame, light)?;
        }
        Ok(())
    }

    /// The technique's diagnostics, and the pixels the framework answered past the frame
    /// ([`BEYOND_FRAME_DIAGNOSTIC`]) where a light's frame reached its widest angle.
    fn diagnostics(&mut self, gpu: &GpuContext) -> Vec<(String, f64)> {
        let mut diagnostics = self.technique.diagnostics(gpu);
        if let Some(beyond_frame) = &self.beyond_frame {
            // A diagnostic that cannot be read is left out rather than reported as zero.
            if let Ok(pixels) = beyond_frame.answered_pixels(gpu) {
                diagnostics.push((BEYOND_FRAME_DIAGNOSTIC.to_owned(), pixels as f64));
            }
        }
        diagnostics
    }

    /// The technique's counts and the framework passes'. A technique that does not count keeps
    /// its reads unknown (`None`): the frame's total would be wrong with the framework's alone.
    fn counted_work(&mut self, gpu: &GpuContext) -> Result<Option<Vec<ShaderWork>>> {
        let Some(mut work) = self.technique.counted_work(gpu)? else {
            return Ok(None);
        };
        if let Some(beyond_frame) = &self.beyond_frame {
            work.extend(beyond_frame.work(gpu)?.unwrap_or_default());
        }
        if let Some(share) = &self.own_surface_share {
            work.extend(share.work(gpu)?.unwrap_or_default());
        }
        Ok(Some(work))
    }

    fn debug_outputs(&mut self, gpu: &GpuContext, requested: &[&str]) -> Result<Vec<crate::ExtraImage>> {
        self.technique.debug_outputs(gpu, requested)
    }
}

/// `technique` followed by the framework's passes that `info` gets: past the frame where a
/// light's frame reaches its widest angle ([`TechniqueInfo::gets_beyond_frame`]), and the
/// own-surface share ([`TechniqueInfo::gets_own_surface_share`]); the technique itself when it
/// gets neither.
///
/// # Errors
/// [`Error::UndeclaredRequirement`](crate::Error::UndeclaredRequirement) without a G-buffer, or a
/// shader error.
pub(crate) fn with_framework_passes(
    technique: Box<dyn ShadowTechnique>,
    setup: &TechniqueSetup<'_>,
    info: &TechniqueInfo,
) -> Result<Box<dyn ShadowTechnique>> {
    let beyond_frame = if info.gets_beyond_frame() { BeyondFrame::new(setup, info.name)? } else { None };
    let own_surface_share = if info.gets_own_surface_share() { Some(OwnSurfaceShare::new(setup, info.name)?) } else { None };
    if beyond_frame.is_none() && own_surface_share.is_none() {
        return Ok(technique);
    }
    Ok(Box::new(WithFrameworkPasses { technique, beyond_frame, own_surface_share }))
}
