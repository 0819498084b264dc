pub mod interval;
pub use interval::Interval;
