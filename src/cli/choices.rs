//! The option values clap parses (`--backend`, `--color`): the command line's twins of
//! the library's [`BackendChoice`] and [`Field`], so the library stays free of clap.

use talus::gpu::device::BackendChoice;
use talus::render::Field;

/// Which path a run uses (`--backend`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Backend {
    /// A GPU adapter when one exists, else the CPU path with a notice.
    Auto,
    Cpu,
    Gpu,
}

impl From<Backend> for BackendChoice {
    fn from(b: Backend) -> BackendChoice {
        match b {
            Backend::Auto => BackendChoice::Auto,
            Backend::Cpu => BackendChoice::Cpu,
            Backend::Gpu => BackendChoice::Gpu,
        }
    }
}

/// What colours the grains (`--color`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Color {
    /// The grain's own pressure, (σ_max + σ_min)/2 of Σ f ⊗ l over its area.
    Pressure,
    /// Its number of contacts.
    Contacts,
    /// Its orientation (the long axis of a polygon).
    Orientation,
    /// One colour; fixed grains grey.
    Plain,
}

impl From<Color> for Field {
    fn from(c: Color) -> Field {
        match c {
            Color::Pressure => Field::Pressure,
            Color::Contacts => Field::Contacts,
            Color::Orientation => Field::Orientation,
            Color::Plain => Field::Plain,
        }
    }
}
