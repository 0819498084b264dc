//! The part file: a [`Part`] as bytes, every float as its IEEE bits, so that a part read back
//! is the part written, bit for bit (docs/results.md, "The part file", describes the layout).
//!
//! Layout (little endian): the magic line `reachc simulate part\n`, the format version (`u32`),
//! the payload, and an FNV-1a 64-bit checksum of everything before it. Strings are a `u64`
//! length and UTF-8 bytes, vectors a `u64` length and their items, options a `u8` flag (0, 1)
//! and the value, enums a `u8` code. Reading checks the magic, the version, the checksum, every
//! length against the bytes left (a corrupt length allocates nothing), every code, and that
//! nothing follows the checksum; a well-formed file can still hold a part [`Part::malformed`]
//! refuses.

use super::dt::{DtSource, DtUsed};
use super::error::{Coded, PartFileError};
use super::inputs::InputMode;
use super::part::{Part, PartStats, RunInfo, StepInfo};
use super::report::{InitialSampling, NoiseKind};
use super::shard::Shard;
use crate::model::{Guarantee, Method};
use crate::prs::UnsafeKind;

/// The first bytes of a part file.
pub const MAGIC: &[u8] = b"reachc simulate part\n";
/// The version of the layout this reachc writes and reads.
pub const FORMAT_VERSION: u32 = 5;

/// FNV-1a, 64 bits.
pub(crate) fn checksum(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Appends values to a byte buffer.
struct Writer(Vec<u8>);

impl Writer {
    fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.u64(v.to_bits());
    }
    fn bool(&mut self, v: bool) {
        self.u8(u8::from(v));
    }
    fn str(&mut self, s: &str) {
        self.u64(s.len() as u64);
        self.0.extend_from_slice(s.as_bytes());
    }
    fn opt_f64(&mut self, v: Option<f64>) {
        self.bool(v.is_some());
        self.f64(v.unwrap_or(0.0));
    }
    fn u64s(&mut self, v: &[u64]) {
        self.u64(v.len() as u64);
        v.iter().for_each(|&x| self.u64(x));
    }
    fn f64s(&mut self, v: &[f64]) {
        self.u64(v.len() as u64);
        v.iter().for_each(|&x| self.f64(x));
    }
}

/// Reads values from bytes; every read is checked.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], PartFileError> {
        let rest = &self.bytes[self.at..];
        if rest.len() < n {
            return Err(PartFileError::Truncated {
                needed: n,
                at: self.at,
            });
        }
        self.at += n;
        Ok(&rest[..n])
    }
    fn u8(&mut self) -> Result<u8, PartFileError> {
        Ok(self.take(1)?[0])
    }
    fn u64(&mut self) -> Result<u64, PartFileError> {
        let b = self.take(8)?;
        let mut a = [0; 8];
        a.copy_from_slice(b);
        Ok(u64::from_le_bytes(a))
    }
    fn f64(&mut self) -> Result<f64, PartFileError> {
        Ok(f64::from_bits(self.u64()?))
    }
    fn bool(&mut self) -> Result<bool, PartFileError> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            byte => Err(PartFileError::Flag {
                byte,
                at: self.at - 1,
            }),
        }
    }
    /// A length of items of `size` bytes, checked against the bytes left.
    fn len(&mut self, size: usize) -> Result<usize, PartFileError> {
        let at = self.at;
        let n = self.u64()?;
        let left = (self.bytes.len() - self.at) as u64;
        if n.saturating_mul(size as u64) > left {
            return Err(PartFileError::Length { length: n, at });
        }
        Ok(n as usize)
    }
    fn str(&mut self) -> Result<String, PartFileError> {
        let n = self.len(1)?;
        let at = self.at;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|_| PartFileError::Utf8 { at })
    }
    fn opt_f64(&mut self) -> Result<Option<f64>, PartFileError> {
        let some = self.bool()?;
        let v = self.f64()?;
        Ok(some.then_some(v))
    }
    fn u64s(&mut self) -> Result<Vec<u64>, PartFileError> {
        (0..self.len(8)?).map(|_| self.u64()).collect()
    }
    fn f64s(&mut self) -> Result<Vec<f64>, PartFileError> {
        (0..self.len(8)?).map(|_| self.f64()).collect()
    }
    /// The enum of code `u8` among `all` (in code order).
    fn code<T: Copy>(&mut self, what: Coded, all: &[T]) -> Result<T, PartFileError> {
        let code = self.u8()?;
        all.get(usize::from(code))
            .copied()
            .ok_or(PartFileError::Code {
                what,
                code,
                at: Some(self.at - 1),
            })
    }
}

const METHODS: [Method; 2] = [Method::Contraction, Method::Interval];
const GUARANTEES: [Guarantee; 2] = [Guarantee::Uniform, Guarantee::Pointwise];
const INPUTS: [InputMode; 3] = [InputMode::Random, InputMode::Corners, InputMode::Centre];
const INITIAL: [InitialSampling; 4] = [
    InitialSampling::Point,
    InitialSampling::Box,
    InitialSampling::Balls,
    InitialSampling::BoxAndBalls,
];
const DT_SOURCES: [DtSource; 2] = [DtSource::Rule, DtSource::Option];
const UNSAFE: [UnsafeKind; 3] = [UnsafeKind::HalfSpace, UnsafeKind::Box, UnsafeKind::Ball];

/// The code of `v` among `all`.
fn code_of<T: PartialEq>(all: &[T], v: &T) -> u8 {
    all.iter().position(|a| a == v).unwrap_or(0) as u8
}

impl Part {
    /// The part file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer(MAGIC.to_vec());
        w.0.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        write_run(&mut w, &self.run);
        w.u64(self.shard.index);
        w.u64(self.shard.count);
        let st = &self.stats;
        w.u64s(&st.outside);
        w.u64(st.outside_any);
        w.u64(st.outside_tube);
        w.u64s(&st.left_tube);
        w.u64s(&st.unsafe_hits);
        w.f64s(&st.first_hit);
        w.u64(st.unsafe_any);
        w.u64s(&st.goal_reached);
        w.u64(st.left_domain);
        w.u64(st.diverged);
        w.u64(self.top.len() as u64);
        self.top.iter().for_each(|t| w.f64s(t));
        w.u64(self.state_top.len() as u64);
        self.state_top.iter().for_each(|t| w.f64s(t));
        let sum = checksum(&w.0);
        w.u64(sum);
        w.0
    }

    /// Reads a part file's bytes, or says why they are not one (not a part file, another
    /// format version, truncated, corrupt).
    pub fn from_bytes(bytes: &[u8]) -> Result<Part, PartFileError> {
        if !bytes.starts_with(MAGIC) {
            return Err(PartFileError::NotAPart);
        }
        let mut r = Reader { bytes, at: 0 };
        r.take(MAGIC.len())?;
        let mut v = [0; 4];
        v.copy_from_slice(r.take(4)?);
        let version = u32::from_le_bytes(v);
        if version != FORMAT_VERSION {
            return Err(PartFileError::Version {
                found: version,
                reads: FORMAT_VERSION,
            });
        }
        let Some(body) = bytes.len().checked_sub(8).filter(|&b| b >= r.at) else {
            return Err(PartFileError::NoChecksum);
        };
        let mut stored = [0; 8];
        stored.copy_from_slice(&bytes[body..]);
        if u64::from_le_bytes(stored) != checksum(&bytes[..body]) {
            return Err(PartFileError::Checksum);
        }
        let mut r = Reader {
            bytes: &bytes[..body],
            at: r.at,
        };
        let run = read_run(&mut r)?;
        let (index, count) = (r.u64()?, r.u64()?);
        let shard = Shard::new(index, count).map_err(PartFileError::Shard)?;
        let stats = PartStats {
            outside: r.u64s()?,
            outside_any: r.u64()?,
            outside_tube: r.u64()?,
            left_tube: r.u64s()?,
            unsafe_hits: r.u64s()?,
            first_hit: r.f64s()?,
            unsafe_any: r.u64()?,
            goal_reached: r.u64s()?,
            left_domain: r.u64()?,
            diverged: r.u64()?,
        };
        let top = (0..r.len(8)?).map(|_| r.f64s()).collect::<Result<_, _>>()?;
        let state_top = (0..r.len(8)?).map(|_| r.f64s()).collect::<Result<_, _>>()?;
        if r.at != body {
            return Err(PartFileError::Unexpected(body - r.at));
        }
        Ok(Part {
            run,
            shard,
            stats,
            top,
            state_top,
        })
    }
}

/// Writes what the parts of a run share (merging compares these bytes too).
fn write_run(w: &mut Writer, run: &RunInfo) {
    w.str(&run.version);
    w.str(&run.spec_hash);
    w.str(&run.model);
    w.str(&run.analysis);
    w.u64(run.states.len() as u64);
    run.states.iter().for_each(|s| w.str(s));
    w.u8(code_of(&METHODS, &run.method));
    w.f64(run.delta);
    w.u8(code_of(&GUARANTEES, &run.guarantee));
    w.f64(run.step);
    w.u64(run.paths);
    w.u64(run.seed);
    w.opt_f64(run.dt_option);
    w.u8(code_of(&INPUTS, &run.inputs));
    w.opt_f64(run.hold_option);
    w.f64(run.confidence);
    w.opt_f64(run.safety_bound);
    let dt = &run.dt;
    w.u8(code_of(&DT_SOURCES, &dt.source));
    w.f64(dt.min);
    w.f64(dt.max);
    w.f64(dt.rule_min);
    w.f64(dt.hl_max);
    w.f64(dt.bias_max);
    w.u64(dt.coarse);
    w.u64(run.steps_per_path);
    w.u8(code_of(&INITIAL, &run.initial_states));
    let (noise, entries) = match run.noise {
        NoiseKind::AdditiveDiagonal => (0, 0),
        NoiseKind::Additive { entries } => (1, entries),
        NoiseKind::StateDependent { entries } => (2, entries),
    };
    w.u8(noise);
    w.u64(entries as u64);
    w.bool(run.has_inputs);
    w.bool(run.tube);
    w.bool(run.has_domain);
    w.u64(run.unsafe_sets.len() as u64);
    for (name, kind) in &run.unsafe_sets {
        w.str(name);
        w.u8(code_of(&UNSAFE, kind));
    }
    w.u64(run.goals.len() as u64);
    for (name, bound) in &run.goals {
        w.str(name);
        w.opt_f64(*bound);
    }
    w.u64(run.quantile_rank);
    w.u64(run.steps.len() as u64);
    for s in &run.steps {
        w.f64(s.t);
        w.f64(s.r_t);
        w.f64(s.prs_radius);
        w.f64s(&s.hull);
    }
    w.u64(run.digest);
}

fn read_run(r: &mut Reader<'_>) -> Result<RunInfo, PartFileError> {
    Ok(RunInfo {
        version: r.str()?,
        spec_hash: r.str()?,
        model: r.str()?,
        analysis: r.str()?,
        states: (0..r.len(8)?).map(|_| r.str()).collect::<Result<_, _>>()?,
        method: r.code(Coded::Method, &METHODS)?,
        delta: r.f64()?,
        guarantee: r.code(Coded::Guarantee, &GUARANTEES)?,
        step: r.f64()?,
        paths: r.u64()?,
        seed: r.u64()?,
        dt_option: r.opt_f64()?,
        inputs: r.code(Coded::Inputs, &INPUTS)?,
        hold_option: r.opt_f64()?,
        confidence: r.f64()?,
        safety_bound: r.opt_f64()?,
        dt: DtUsed {
            source: r.code(Coded::DtSource, &DT_SOURCES)?,
            min: r.f64()?,
            max: r.f64()?,
            rule_min: r.f64()?,
            hl_max: r.f64()?,
            bias_max: r.f64()?,
            coarse: r.u64()?,
        },
        steps_per_path: r.u64()?,
        initial_states: r.code(Coded::InitialSampling, &INITIAL)?,
        noise: {
            let code = r.u8()?;
            let entries = usize::try_from(r.u64()?).map_err(|_| PartFileError::NoiseEntries)?;
            match code {
                0 => NoiseKind::AdditiveDiagonal,
                1 => NoiseKind::Additive { entries },
                2 => NoiseKind::StateDependent { entries },
                code => {
                    return Err(PartFileError::Code {
                        what: Coded::Noise,
                        code,
                        at: None,
                    })
                }
            }
        },
        has_inputs: r.bool()?,
        tube: r.bool()?,
        has_domain: r.bool()?,
        unsafe_sets: (0..r.len(9)?)
            .map(|_| Ok((r.str()?, r.code(Coded::UnsafeSet, &UNSAFE)?)))
            .collect::<Result<_, PartFileError>>()?,
        goals: (0..r.len(9)?)
            .map(|_| Ok((r.str()?, r.opt_f64()?)))
            .collect::<Result<_, PartFileError>>()?,
        quantile_rank: r.u64()?,
        steps: (0..r.len(32)?)
            .map(|_| {
                Ok(StepInfo {
                    t: r.f64()?,
                    r_t: r.f64()?,
                    prs_radius: r.f64()?,
                    hull: r.f64s()?,
                })
            })
            .collect::<Result<_, PartFileError>>()?,
        digest: r.u64()?,
    })
}

/// The bytes of `run` as a part file holds them: equal bytes, the same run to the bit.
pub(crate) fn run_bytes(run: &RunInfo) -> Vec<u8> {
    let mut w = Writer(Vec::new());
    write_run(&mut w, run);
    w.0
}
