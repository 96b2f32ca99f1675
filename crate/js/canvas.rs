//! The page's drawing backend: plotters-canvas's [`CanvasBackend`] with text measured by the
//! canvas itself and the 2-D context's state set only when it changes.
//!
//! plotters measures text on the web by appending a `<span>` to the document and reading its
//! size, which forces a layout of the whole page for every tick label — about a fifth of a
//! playground frame. [`Canvas`] answers [`DrawingBackend::estimate_text_size`] with the 2-D
//! context's `measureText` in the same font string `CanvasBackend::draw_text` sets, so the
//! size is that of the text as it will be drawn, and nothing touches the DOM.
//!
//! Lines, paths, rectangles and text — hundreds per chart (grid lines, tick labels) — are drawn
//! here as `CanvasBackend` draws them, except that the stroke style, line width, fill style,
//! font and text alignment are written to the context only when they differ from what was last
//! written: each write formats a CSS string that the browser then parses. Consecutive lines
//! (or circles) of one style become one path with one `stroke` (or `fill`; overlapping
//! translucent circles are then filled once, not twice). Text sizes are remembered across
//! frames (the same tick labels come back on every edit), and so are the JS strings of texts,
//! fonts and colours, passed to the context as they are instead of decoded from UTF-8 on every
//! call. A polyline is drawn through the vertices that keep every point within a quarter pixel
//! ([`crate::chart::simplify_polyline`]): a third of the `lineTo` calls of a 4-shaper frame.
//! Bitmaps (the sensitivity map) are written with one `putImageData`. Everything else is
//! delegated to `CanvasBackend`, after which the remembered state is forgotten (it may have
//! changed it). Compiled only for wasm32.

use plotters::prelude::DrawingBackend;
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingErrorKind, FontTransform,
};
use plotters_canvas::CanvasBackend;
use std::cell::RefCell;
use std::collections::HashMap;
use wasm_bindgen::prelude::wasm_bindgen;
use wasm_bindgen::{Clamped, JsCast, JsValue};
use web_sys::{CanvasRenderingContext2d, HtmlCanvasElement, ImageData};

// The 2-D context's text and style entry points taking a JS string already made (web-sys's take
// `&str`, which the glue decodes from UTF-8 into a new JS string on every call).
#[wasm_bindgen]
extern "C" {
    /// A `CanvasRenderingContext2D`, seen through the entry points below.
    type Context2d;
    #[wasm_bindgen(method, js_name = fillText)]
    fn fill_text_js(this: &Context2d, text: &JsValue, x: f64, y: f64);
    #[wasm_bindgen(method, setter = font)]
    fn set_font_js(this: &Context2d, font: &JsValue);
    #[wasm_bindgen(method, setter = fillStyle)]
    fn set_fill_style_js(this: &Context2d, style: &JsValue);
    #[wasm_bindgen(method, setter = strokeStyle)]
    fn set_stroke_style_js(this: &Context2d, style: &JsValue);
}

/// What was last written to the context (`None`: unknown).
#[derive(Debug, Default)]
struct ContextState {
    stroke: Option<(Rgba, u32)>,
    fill: Option<Rgba>,
    font: Option<String>,
    align: Option<(&'static str, &'static str)>,
    /// What the current path holds that is not yet stroked or filled (in the style above).
    open: Open,
    /// Scratch space for a polyline's vertices.
    path: Vec<(i32, i32)>,
}

/// The shapes collected in the current path, drawn by one `stroke` or `fill` when something
/// else is drawn ([`Canvas::flush`]).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
enum Open {
    #[default]
    Nothing,
    /// Lines, in the stroke style.
    Lines,
    /// Circles, filled in the fill style (`true`) or outlined in the stroke style.
    Circles(bool),
}

thread_local! {
    /// Text sizes already measured, by (font, text): tick labels repeat from frame to frame,
    /// and each `measureText` is a call into the browser with the text decoded into a JS
    /// string. Cleared when it grows past [`MEASURED_MAX`] entries.
    static MEASURED: RefCell<HashMap<(String, String), (u32, u32)>> = RefCell::new(HashMap::new());
    /// JS strings of the texts, fonts and colours already passed to the context, by their Rust
    /// text: the same few hundred come back on every frame, and making a JS string from UTF-8
    /// costs more than the call that uses it. Cleared when it grows past [`MEASURED_MAX`].
    static JS_STRINGS: RefCell<HashMap<String, JsValue>> = RefCell::new(HashMap::new());
}

/// Calls `f` with `text` as a JS string, made once and then reused ([`JS_STRINGS`]).
fn with_js_string<R>(text: &str, f: impl FnOnce(&JsValue) -> R) -> R {
    JS_STRINGS.with(|m| {
        let mut m = m.borrow_mut();
        if let Some(v) = m.get(text) {
            return f(v);
        }
        if m.len() >= MEASURED_MAX {
            m.clear();
        }
        let v = JsValue::from_str(text);
        let r = f(&v);
        m.insert(text.to_owned(), v);
        r
    })
}

/// How far (in canvas pixels) a polyline's dropped points may lie from the segments drawn
/// instead: a quarter of a pixel, a sixth of the thinnest series line (1.5 px).
const PATH_TOLERANCE: f64 = 0.25;

/// Most text sizes [`MEASURED`] keeps.
const MEASURED_MAX: usize = 4096;

/// A canvas backend whose text measurement does not force a page layout (module docs).
pub(crate) struct Canvas {
    inner: CanvasBackend,
    context: CanvasRenderingContext2d,
    state: RefCell<ContextState>,
}

/// A colour compared by value (alpha by its bits), so an unchanged style is recognised
/// without formatting its CSS string.
type Rgba = ((u8, u8, u8), u64);

fn rgba(color: BackendColor) -> Rgba {
    (color.rgb, color.alpha.to_bits())
}

/// plotters-canvas's colour string.
fn css_color(color: BackendColor) -> String {
    let (r, g, b) = color.rgb;
    format!("rgba({},{},{},{})", r, g, b, color.alpha)
}

/// The font string `CanvasBackend::draw_text` sets.
fn css_font<S: BackendTextStyle>(style: &S) -> String {
    format!(
        "{} {}px {}",
        style.style().as_str(),
        style.size(),
        style.family().as_str(),
    )
}

/// Moves a horizontal or vertical line to the half pixel, as plotters-canvas does, so it is
/// not blurred over two pixels.
fn fine_lines(from: BackendCoord, to: BackendCoord) -> ((f64, f64), (f64, f64)) {
    let (mut a, mut b) = (
        (f64::from(from.0), f64::from(from.1)),
        (f64::from(to.0), f64::from(to.1)),
    );
    if a.0 == b.0 {
        a.0 -= 0.5;
        b.0 -= 0.5;
    }
    if a.1 == b.1 {
        a.1 -= 0.5;
        b.1 -= 0.5;
    }
    (a, b)
}

impl Canvas {
    /// The backend for `canvas`, or `None` if it has no 2-D context.
    #[cfg_attr(
        not(any(feature = "js-playground", feature = "js-recording")),
        allow(dead_code)
    )] // the designer module draws nothing
    pub(crate) fn new(canvas: HtmlCanvasElement) -> Option<Canvas> {
        let context = canvas
            .get_context("2d")
            .ok()
            .flatten()?
            .dyn_into::<CanvasRenderingContext2d>()
            .ok()?;
        Some(Canvas {
            inner: CanvasBackend::with_canvas_object(canvas)?,
            context,
            state: RefCell::default(),
        })
    }

    /// The context, for the JS-string entry points.
    fn js(&self) -> &Context2d {
        self.context.unchecked_ref()
    }

    /// Sets the stroke colour and width unless they are already set.
    fn line_style<S: BackendStyle>(&self, style: &S) {
        let want = (rgba(style.color()), style.stroke_width());
        let mut st = self.state.borrow_mut();
        if st.stroke != Some(want) {
            with_js_string(&css_color(style.color()), |c| {
                self.js().set_stroke_style_js(c)
            });
            self.context.set_line_width(f64::from(want.1));
            st.stroke = Some(want);
        }
    }

    /// Sets the fill colour unless it is already set.
    fn fill_style(&self, color: BackendColor) {
        let want = rgba(color);
        let mut st = self.state.borrow_mut();
        if st.fill != Some(want) {
            with_js_string(&css_color(color), |c| self.js().set_fill_style_js(c));
            st.fill = Some(want);
        }
    }

    /// Sets the font unless it is already set.
    fn font<S: BackendTextStyle>(&self, style: &S) {
        let want = css_font(style);
        let mut st = self.state.borrow_mut();
        if st.font.as_ref() != Some(&want) {
            with_js_string(&want, |f| self.js().set_font_js(f));
            st.font = Some(want);
        }
    }

    /// Strokes or fills the shapes collected in the current path, if any. Every drawing
    /// operation that does not add to the path calls this first, so the drawing order is kept.
    fn flush(&self) {
        let mut st = self.state.borrow_mut();
        match std::mem::take(&mut st.open) {
            Open::Nothing => {}
            Open::Lines | Open::Circles(false) => self.context.stroke(),
            Open::Circles(true) => self.context.fill(),
        }
    }

    /// Makes the current path collect `open` shapes: if it already does in this style,
    /// nothing; otherwise the collected shapes are drawn, the style set and a path begun.
    fn collect<S: BackendStyle>(&self, open: Open, style: &S) {
        let same = {
            let st = self.state.borrow();
            st.open == open
                && match open {
                    Open::Circles(true) => st.fill == Some(rgba(style.color())),
                    _ => st.stroke == Some((rgba(style.color()), style.stroke_width())),
                }
        };
        if !same {
            self.flush();
            match open {
                Open::Circles(true) => self.fill_style(style.color()),
                _ => self.line_style(style),
            }
            self.context.begin_path();
            self.state.borrow_mut().open = open;
        }
    }

    /// After a call delegated to `CanvasBackend`, which may have set any of the state.
    fn forget(&self) {
        *self.state.borrow_mut() = ContextState::default();
    }
}

impl Drop for Canvas {
    /// Draws the shapes still collected when the chart is done with the backend.
    fn drop(&mut self) {
        self.flush();
    }
}

type Failure = DrawingErrorKind<<CanvasBackend as DrawingBackend>::ErrorType>;

impl DrawingBackend for Canvas {
    type ErrorType = <CanvasBackend as DrawingBackend>::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), Failure> {
        self.inner.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), Failure> {
        self.flush();
        self.inner.present()
    }

    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Result<(), Failure> {
        self.flush();
        self.forget();
        self.inner.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), Failure> {
        if style.color().alpha == 0.0 {
            return Ok(());
        }
        // Consecutive lines of one style (a chart's grid lines, its tick marks) are one path
        // and one `stroke`: each stroke is a separate draw the browser records and rasterises.
        let (a, b) = fine_lines(from, to);
        self.collect(Open::Lines, style);
        self.context.move_to(a.0, a.1);
        self.context.line_to(b.0, b.1);
        Ok(())
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), Failure> {
        if style.color().alpha == 0.0 {
            return Ok(());
        }
        self.flush();
        let (x, y) = (f64::from(upper_left.0), f64::from(upper_left.1));
        let (w, h) = (
            f64::from(bottom_right.0 - upper_left.0),
            f64::from(bottom_right.1 - upper_left.1),
        );
        if fill {
            self.fill_style(style.color());
            self.context.fill_rect(x, y, w, h);
        } else {
            self.line_style(style);
            self.context.stroke_rect(x, y, w, h);
        }
        Ok(())
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), Failure> {
        if style.color().alpha == 0.0 {
            return Ok(());
        }
        self.flush();
        // Only the vertices the drawing needs (within PATH_TOLERANCE px of every point).
        let mut points = std::mem::take(&mut self.state.borrow_mut().path);
        crate::chart::simplify_polyline(path, PATH_TOLERANCE, &mut points);
        self.context.begin_path();
        if let Some((start, rest)) = points.split_first() {
            self.line_style(style);
            self.context.move_to(f64::from(start.0), f64::from(start.1));
            for next in rest {
                self.context.line_to(f64::from(next.0), f64::from(next.1));
            }
        }
        self.context.stroke();
        self.state.borrow_mut().path = points;
        Ok(())
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), Failure> {
        // Markers of one style (an impulse chart's stem heads) are one path, as lines are.
        if style.color().alpha == 0.0 {
            return Ok(());
        }
        self.collect(Open::Circles(fill), style);
        let (x, y, r) = (f64::from(center.0), f64::from(center.1), f64::from(radius));
        self.context.move_to(x + r, y);
        if self
            .context
            .arc(x, y, r, 0.0, std::f64::consts::TAU)
            .is_err()
        {
            // Never seen (a negative radius): draw what was collected and let CanvasBackend
            // report it.
            self.flush();
            self.forget();
            return self.inner.draw_circle(center, radius, style, fill);
        }
        Ok(())
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), Failure> {
        self.flush();
        self.forget();
        self.inner.fill_polygon(vert, style)
    }

    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), Failure> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        self.flush();
        let degrees = match style.transform() {
            FontTransform::None => 0.0,
            FontTransform::Rotate90 => 90.0,
            FontTransform::Rotate180 => 180.0,
            FontTransform::Rotate270 => 270.0,
        };
        if degrees != 0.0 {
            // Rotated text (axis titles, a few per chart) goes through CanvasBackend.
            self.forget();
            return self.inner.draw_text(text, style, pos);
        }
        let baseline = match style.anchor().v_pos {
            VPos::Top => "top",
            VPos::Center => "middle",
            VPos::Bottom => "bottom",
        };
        let align = match style.anchor().h_pos {
            HPos::Left => "start",
            HPos::Right => "end",
            HPos::Center => "center",
        };
        {
            let mut st = self.state.borrow_mut();
            if st.align != Some((align, baseline)) {
                self.context.set_text_baseline(baseline);
                self.context.set_text_align(align);
                st.align = Some((align, baseline));
            }
        }
        self.fill_style(color);
        self.font(style);
        // fillText throws only for a non-finite position, which integer pixels are not.
        with_js_string(text, |t| {
            self.js()
                .fill_text_js(t, f64::from(pos.0), f64::from(pos.1))
        });
        Ok(())
    }

    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> Result<(u32, u32), Failure> {
        // The font string draw_text sets before fill_text.
        let key = (css_font(style), text.to_owned());
        if let Some(size) = MEASURED.with(|m| m.borrow().get(&key).copied()) {
            return Ok(size);
        }
        self.font(style);
        match self.context.measure_text(text) {
            Ok(m) => {
                let height = m.font_bounding_box_ascent() + m.font_bounding_box_descent();
                let height = if height.is_finite() && height > 0.0 {
                    height
                } else {
                    1.15 * style.size()
                };
                let size = (m.width().max(0.0).ceil() as u32, height.ceil() as u32);
                MEASURED.with(|m| {
                    let mut m = m.borrow_mut();
                    if m.len() >= MEASURED_MAX {
                        m.clear();
                    }
                    m.insert(key, size);
                });
                Ok(size)
            }
            // No measurement (never seen): fall back to plotters' own.
            Err(_) => self.inner.estimate_text_size(text, style),
        }
    }

    /// One `putImageData` of the RGB bitmap (plotters' pixel-by-pixel default would be a
    /// `fillRect` per pixel); falls back to the default if the context refuses it.
    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        (w, h): (u32, u32),
        src: &[u8],
    ) -> Result<(), Failure> {
        self.flush();
        let pixels = w as usize * h as usize;
        if w == 0 || h == 0 || src.len() < 3 * pixels {
            self.forget();
            return self.inner.blit_bitmap(pos, (w, h), src);
        }
        let mut rgba = vec![255; 4 * pixels];
        for (to, from) in rgba.chunks_exact_mut(4).zip(src.chunks_exact(3)) {
            // Byte by byte: a 3-byte `copy_from_slice` can be a `memcpy` call per pixel at
            // opt-level "z".
            to[0] = from[0];
            to[1] = from[1];
            to[2] = from[2];
        }
        let image = ImageData::new_with_u8_clamped_array_and_sh(Clamped(&rgba), w, h);
        match image.and_then(|img| {
            self.context
                .put_image_data(&img, f64::from(pos.0), f64::from(pos.1))
        }) {
            Ok(()) => Ok(()),
            Err(_) => {
                self.forget();
                self.inner.blit_bitmap(pos, (w, h), src)
            }
        }
    }
}
