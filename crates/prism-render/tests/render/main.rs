//! prism-render's integration tests: the path tracer against closed forms and Mitsuba
//! (`paths`), split renders and their merge (`parts`), and the Whitted ray tracer (`whitted`) with its extras (`whitted_extras`).

mod mitsuba_xml;
mod parts;
mod paths;
mod whitted;
mod whitted_extras;
