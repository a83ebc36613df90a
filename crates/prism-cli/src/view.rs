//! `prism view`: the window around prism-view's [`Viewer`]: winit for the window and its
//! events, Xlib's `XPutImage` for CPU-drawn pixels, X11 loaded at run time (so it runs over
//! SSH with X forwarding and under Xvfb, and needs no GPU).

use std::path::PathBuf;
use std::rc::Rc;

use anyhow::Result;
use clap::{Args, ValueEnum};
use prism_raster::{read_svg, Dialect};
use prism_view::{ClothMode, Input, Key, MeshMode, PathMode, SvgMode, Viewer, WhittedMode};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key as WinitKey, ModifiersState, NamedKey};
use winit::window::{Window, WindowId};

use crate::error::UserError;
use crate::present::Presenter;

/// What the file is viewed as.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// An SVG drawing through the rasterizer (the course viewer's controls).
    Svg,
    /// A lit COLLADA scene, path-traced progressively.
    Path,
    /// A ClothSim scene JSON, simulated and shaded as the course app plays it.
    Cloth,
    /// A Delft scene (a preset name, an OBJ scene or a TOML config) through the Whitted ray
    /// tracer, with its ray trees and BVH views.
    Whitted,
    /// A mesh (OBJ, PLY, COLLADA) to edit as MeshEdit does.
    Mesh,
}

/// Arguments of `prism view`.
#[derive(Args, Debug)]
#[command(after_help = "Controls (also on screen with H):
  all modes  H help overlay, Esc quit
  svg        - = fewer/more samples per pixel (1, 4, 9, 16), P pixel sampling
             (nearest/bilinear), L level sampling (level 0/nearest/trilinear), drag to
             pan, wheel to zoom about the cursor, R reset the view, S save a screenshot
             PNG (FILE-screenshot-N.png in the current folder)
  path       one sample per pixel a frame (the picture after n passes is prism render
             -s n); drag orbits the camera, the wheel moves it closer, 1-9 only the m-th
             bounce, 0 every bounce, A adaptive sampling and its heat map (M: heat map or
             picture), R reset the camera
  cloth      P play/pause, N one frame, R back to the start, C next shader (phong,
             diffuse, normal, wireframe), drag to orbit, wheel to move closer
  whitted    click a pixel to trace its rays (kept while the camera orbits), X clear them,
             drag to orbit (half resolution until the camera rests), wheel to move
             closer, 1-9 0 M toggle shading, recursive, hard shadow, soft shadow, normal
             interpolation, texture, bilinear, bvh, bloom, transparency, multi-rays; D B G E
             P A toggle depth of field, motion blur, glossy, environment map, mip-mapping,
             SAH binning; [ ] BVH level, , . BVH leaf, R reset the camera
  mesh       hover highlights the vertex, edge or face under the cursor; F flip, S split,
             C collapse the highlighted edge, U Loop subdivision, N smooth/flat normals,
             W wireframe, Ctrl+Z undo, Ctrl+S save as NAME-edited.obj; drag orbits, wheel
             zooms, arrows pan, R resets the view")]
pub struct ViewArgs {
    /// The file to open; its extension chooses the mode (.svg: svg; .xml (Mitsuba 3): path;
    /// .json: cloth; .obj,
    /// .toml or a Delft preset name such as cornell-box: whitted; .ply: mesh; .dae: path if
    /// it has lights of its own, mesh if it is lit only by a modelling tool's default lamp
    /// (a white point or directional light and no emitting material, as every MeshEdit
    /// file is) or not at all).
    file: PathBuf,
    /// The mode, instead of the one the extension chooses.
    #[arg(long, value_enum)]
    mode: Option<ModeArg>,
    /// Reproduce another renderer: `cs184` reads SVG as the CS184 course dialect (its
    /// elements, quirks and view), as `prism svg --compat cs184`.
    #[arg(long, value_enum)]
    compat: Option<crate::svg::Compat>,
    /// Window size: WIDTH HEIGHT (default 960 640; 512 384 for path tracing; 1024 800, the
    /// course app's, for cloth; the config's window or 800 800 for whitted).
    #[arg(short = 'r', long = "resolution", num_args = 2, value_names = ["WIDTH", "HEIGHT"])]
    resolution: Option<Vec<u32>>,
    /// Seed of the path tracer's random numbers.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Cloth: override a scene value, as `prism cloth --set` (`--set ks=500`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// The course's files (`shared/assets`), where the Delft presets' OBJ files are found
    /// (default: PRISM_DATA, else a `shared/assets` folder above the executable or the
    /// working folder, else the copies built into prism).
    #[arg(long, value_name = "DIR")]
    data: Option<PathBuf>,
    /// Worker threads (default: one per core).
    #[arg(short = 't', long)]
    threads: Option<usize>,
}

/// The mode for `a.file`.
fn open(a: &ViewArgs) -> Result<Viewer> {
    crate::error::check_scene_name(&a.file.to_string_lossy())?;
    let mut chosen = None;
    let viewer = open_mode(a, &mut chosen)?;
    Ok(match chosen {
        Some(m) => viewer.with_message(m.to_string()),
        None => viewer,
    })
}

/// The viewer of `a.file` in the mode `--mode` names or its extension chooses; `chosen`
/// is set to a line saying why when the choice was not plain from the extension.
fn open_mode(a: &ViewArgs, chosen: &mut Option<&'static str>) -> Result<Viewer> {
    let mode = match a.mode {
        Some(m) => m,
        None => match crate::output::extension(&a.file).as_str() {
            "svg" => ModeArg::Svg,
            "dae" => {
                let lamp = prism_scene::load(&a.file, &prism_scene::SceneOptions::default())
                    .map(|s| s.lit_only_by_a_default_lamp())
                    .unwrap_or(false);
                if lamp {
                    *chosen = Some(
                        "mesh mode: no light of its own (--mode path to path-trace it)",
                    );
                    ModeArg::Mesh
                } else {
                    *chosen = Some("path mode: the scene's own lights (--mode mesh to edit it)");
                    ModeArg::Path
                }
            }
            "ply" => ModeArg::Mesh,
            "xml" => ModeArg::Path,
            "json" => ModeArg::Cloth,
            "obj" | "toml" => ModeArg::Whitted,
            "" if prism_scene::Preset::from_name(&a.file.to_string_lossy()).is_some() => {
                ModeArg::Whitted
            }
            other => {
                return Err(UserError::Refused(format!(
                    "{}: cannot tell what to view from the extension `.{other}`; prism view \
                     opens .svg drawings, lit .dae scenes, cloth .json scenes and Delft .obj, .toml \
                     or preset scenes, and .ply meshes (--mode svg, path, cloth, whitted or mesh)",
                    a.file.display()
                ))
                .into())
            }
        },
    };
    let (w, h) = match (&a.resolution, mode) {
        (Some(r), _) => (r[0], r[1]),
        (None, ModeArg::Svg) => (960, 640),
        (None, ModeArg::Path) => (512, 384),
        (None, ModeArg::Cloth) => (1024, 800),
        (None, ModeArg::Whitted) => (800, 800),
        (None, ModeArg::Mesh) => (960, 720),
    };
    if !(1..=prism_raster::MAX_DIMENSION).contains(&w)
        || !(1..=prism_raster::MAX_DIMENSION).contains(&h)
    {
        return Err(UserError::Refused(format!(
            "--resolution: expected 1 to {} pixels a side, found {w} x {h}",
            prism_raster::MAX_DIMENSION
        ))
        .into());
    }
    match mode {
        ModeArg::Svg => {
            let dialect = if a.compat.is_some() {
                Dialect::Cs184
            } else {
                Dialect::Svg
            };
            let doc = read_svg(&a.file, dialect).map_err(UserError::input)?;
            for w in &doc.warnings {
                eprintln!("warning: {w}");
            }
            let here = std::env::current_dir()?;
            let mode = SvgMode::new(doc, &a.file, dialect, &here);
            Ok(Viewer::new(Box::new(mode), w, h))
        }
        ModeArg::Path => {
            let scene = prism_scene::load(&a.file, &prism_scene::SceneOptions::default())
                .map_err(UserError::input)?;
            for w in &scene.warnings {
                eprintln!("warning: {w}");
            }
            if !scene.is_lit() {
                return Err(UserError::Refused(format!(
                    "{}: the scene has no light, so path tracing shows black; prism view \
                     opens lit scenes",
                    a.file.display()
                ))
                .into());
            }
            let mode = PathMode::new(&scene, &a.file, a.seed);
            Ok(Viewer::new(Box::new(mode), w, h))
        }
        ModeArg::Whitted => {
            let name = a.file.to_string_lossy();
            let loaded = prism_scene::load_delft(&name, a.data.as_deref(), &mut |w| {
                eprintln!("prism: warning: {w}");
            })
            .map_err(UserError::input)?;
            let (w, h) = match (&a.resolution, loaded.window) {
                (None, Some([cw, ch])) => (cw, ch),
                _ => (w, h),
            };
            let camera = loaded.cameras.first().copied().unwrap_or_default();
            let name = a.file.display().to_string();
            let mode = WhittedMode::new(loaded.scene, &name, camera, loaded.features).with_extras(
                loaded.extras,
                loaded.motion,
                loaded.environment,
            );
            Ok(Viewer::new(Box::new(mode), w, h))
        }
        ModeArg::Mesh => {
            let (poly, warnings) = prism_scene::read_mesh(&a.file).map_err(UserError::input)?;
            for w in &warnings {
                eprintln!("warning: {w}");
            }
            let mesh = prism_mesh::HalfedgeMesh::from_polymesh(&poly)
                .map_err(|e| UserError::input(format!("{}: {e}", a.file.display())))?;
            Ok(Viewer::new(Box::new(MeshMode::new(mesh, &a.file)), w, h))
        }
        ModeArg::Cloth => {
            let scene = prism_cloth::read_scene(&a.file, &a.set).map_err(UserError::input)?;
            Ok(Viewer::new(Box::new(ClothMode::new(scene, &a.file)), w, h))
        }
    }
}

/// Runs `prism view`.
pub fn run(a: &ViewArgs) -> Result<()> {
    // The window's events stay on the main thread; the modes' workers (path tracing,
    // shading, rasterizing) run on the global pool.
    crate::resources::global_pool(a.threads)?;
    let viewer = open(a)?;
    if std::env::var_os("DISPLAY").is_none_or(|d| d.is_empty()) {
        return Err(UserError::Refused(
            "prism view needs an X11 display, and DISPLAY is not set (over SSH, connect with \
             ssh -X; headless, start Xvfb :99 and set DISPLAY=:99)"
                .into(),
        )
        .into());
    }
    let event_loop = EventLoop::new().map_err(|e| {
        UserError::Refused(format!(
            "prism view: cannot reach the display: {}",
            without_source_location(&e.to_string())
        ))
    })?;
    let mut app = App {
        viewer,
        window: None,
        surface: None,
        modifiers: ModifiersState::empty(),
        error: None,
    };
    event_loop.run_app(&mut app)?;
    match app.error {
        Some(e) => {
            Err(UserError::Refused(format!("prism view: {}", without_source_location(&e))).into())
        }
        None => Ok(()),
    }
}

/// `text` without the windowing library's note of where in its own source an OS error was
/// raised (`os error at /.../winit-0.30/src/....rs:788: `), which says nothing to a user.
fn without_source_location(text: &str) -> String {
    const MARK: &str = "os error at ";
    let Some(at) = text.find(MARK) else {
        return text.to_string();
    };
    let rest = &text[at + MARK.len()..];
    // The location ends at the first ": " after `FILE:LINE`.
    match rest
        .find(".rs:")
        .and_then(|i| rest[i..].find(": ").map(|j| i + j + 2))
    {
        Some(end) => format!("{}{}", &text[..at], &rest[end..]),
        None => text.to_string(),
    }
}

/// The window, its pixel surface and the viewer.
struct App {
    viewer: Viewer,
    window: Option<Rc<Window>>,
    surface: Option<Presenter>,
    modifiers: ModifiersState,
    error: Option<String>,
}

impl App {
    fn send(&mut self, input: Input, event_loop: &ActiveEventLoop) {
        if self.viewer.input(input) {
            if let Some(w) = &self.window {
                w.request_redraw();
            }
        }
        if self.viewer.quit() {
            event_loop.exit();
        }
    }

    fn redraw(&mut self) -> Result<(), String> {
        let frame = self.viewer.frame().image;
        let (w, h) = (frame.width(), frame.height());
        let Some(surface) = self.surface.as_mut() else {
            return Ok(());
        };
        surface
            .show(frame.pixels().iter().map(|p| [p[0], p[1], p[2]]), w, h)
            .map_err(|e| e.to_string())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let attributes = Window::default_attributes()
            .with_title(self.viewer.title())
            .with_inner_size(winit::dpi::PhysicalSize::new(
                self.viewer.size().0,
                self.viewer.size().1,
            ));
        let made = event_loop
            .create_window(attributes)
            .map_err(|e| e.to_string())
            .and_then(|w| {
                let surface = Presenter::new(&w).map_err(|e| e.to_string())?;
                Ok((Rc::new(w), surface))
            });
        match made {
            Ok((w, surface)) => {
                w.request_redraw();
                self.window = Some(w);
                self.surface = Some(surface);
            }
            Err(e) => {
                self.error = Some(format!("cannot open a window: {e}"));
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => self.send(
                Input::Resize {
                    width: size.width,
                    height: size.height,
                },
                event_loop,
            ),
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw() {
                    self.error = Some(format!("cannot draw: {e}"));
                    event_loop.exit();
                } else if self.viewer.busy() {
                    if let Some(w) = &self.window {
                        w.request_redraw();
                    }
                }
            }
            WindowEvent::ModifiersChanged(m) => self.modifiers = m.state(),
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                let key = match &event.logical_key {
                    WinitKey::Named(NamedKey::Escape) => Some(Key::Escape),
                    WinitKey::Named(NamedKey::ArrowLeft) => Some(Key::Left),
                    WinitKey::Named(NamedKey::ArrowRight) => Some(Key::Right),
                    WinitKey::Named(NamedKey::ArrowUp) => Some(Key::Up),
                    WinitKey::Named(NamedKey::ArrowDown) => Some(Key::Down),
                    WinitKey::Character(s) => {
                        s.chars().next().map(|c| Key::Char(c.to_ascii_lowercase()))
                    }
                    _ => None,
                };
                if let Some(key) = key {
                    let ctrl = self.modifiers.control_key();
                    self.send(Input::Key { key, ctrl }, event_loop);
                }
            }
            WindowEvent::CursorMoved { position, .. } => self.send(
                Input::Cursor {
                    x: position.x,
                    y: position.y,
                },
                event_loop,
            ),
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => self.send(Input::Button(state == ElementState::Pressed), event_loop),
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => f64::from(y),
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                self.send(Input::Wheel(lines), event_loop);
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::without_source_location;

    /// The windowing library's source location is cut from its errors; other text is kept.
    #[test]
    fn source_locations_are_cut() {
        let winit = "os error at /root/.cargo/registry/src/index.crates.io-1/winit-0.30.13/src/\
                     platform_impl/linux/mod.rs:788: Failed to open connection to X server";
        assert_eq!(
            without_source_location(winit),
            "Failed to open connection to X server"
        );
        assert_eq!(
            without_source_location("cannot draw: os error at a/b.rs:1: gone"),
            "cannot draw: gone"
        );
        assert_eq!(without_source_location("plain"), "plain");
    }
}
