//! Volume files: teem's NRRD format ("nearly raw raster data") and headerless raw bytes, read
//! into a [`Grid`]; NRRD written back, for tests and for Mirador's sample data.
//!
//! # NRRD in brief
//!
//! A NRRD file is a short text header that describes the samples, then the samples:
//!
//! ```text
//! NRRD0004                      the magic: NRRD0001 to NRRD0005, the format's version
//! # a comment
//! type: unsigned short          field: value
//! dimension: 3
//! sizes: 256 256 128            samples per axis, the fastest-varying axis first
//! spacings: 0.9 0.9 1.5
//! endian: little
//! encoding: gzip
//! scanner:=CT 3                 key:=value, free text (read past)
//!                               a blank line ends the header
//! <the samples, gzip-compressed>
//! ```
//!
//! The data follows the blank line ("attached", a `.nrrd` file), or the header names a file that
//! holds it with `data file: name.raw` ("detached", usually a `.nhdr` file, which may end at the
//! end of the file instead of at a blank line). The name is relative to the header's folder.
//! Samples are stored with the first axis of `sizes` fastest: Mirador's x, then y, then z, the
//! order of [`Grid::values`].
//!
//! | field | what it says | what Mirador does with it |
//! |---|---|---|
//! | `type` | the sample type: `uchar`, `short`, `float`, … (C's and `stdint.h`'s spellings) | [`ScalarType`]; each sample becomes the `f32` of its numeric value, not normalized |
//! | `dimension` | the number of axes | must be 3 |
//! | `sizes` | samples per axis | [`Grid::dims`]: at least 2, at most [`MAX_DIM`] per axis, [`MAX_VOXELS`] in all |
//! | `spacings` | the distance between samples on each axis | [`Grid::spacing`] |
//! | `space directions` | each axis's step as a vector, e.g. `(0.9,0,0) (0,0.9,0) (0,0,1.5)` | the vectors' lengths, when there is no `spacings`; the orientation is dropped |
//! | `encoding` | `raw`, `gzip` (`gz`), `ascii` (`text`, `txt`); also `hex`, `bzip2` | the first three |
//! | `endian` | the byte order of multi-byte samples, `little` or `big` | required for 2-, 4- and 8-byte types, except in ascii |
//! | `line skip`, `byte skip` | lines, then bytes, to skip before the data | byte skip counts decompressed bytes under gzip; `byte skip: -1` (raw only): the data is the last bytes of the file |
//! | `data file` | the detached data | one file; the `LIST` and numbered-series forms are refused |
//! | `kinds` | what each axis is | an axis that is not spatial (`RGB-color`, `vector`, …) is refused: a volume's three axes are all space |
//!
//! Spacing is 1 on every axis when neither `spacings` nor `space directions` is given. The
//! other standard fields (`space`, `space origin`, `centerings`, `content`, `min`, `max`, `labels`,
//! `units`, …) are read past; unknown fields are read past with a warning. As in teem, field
//! names and the words Mirador reads in values (`Float`, `GZIP`, `Little`) are case-insensitive;
//! file names are not.
//!
//! # Raw files
//!
//! Headerless samples ([`read_raw`]) carry nothing but the bytes, so the caller says what they
//! are ([`RawDesc`]). The file's size must then be exactly what that description needs: a raw
//! file read with the wrong dimensions or type is the usual mistake, and a size that does not
//! match is the only sign of it.
//!
//! # Bad input
//!
//! Every problem is an `Err` that says what is wrong (header problems name their line); nothing
//! panics. The grid's size is checked against [`MAX_DIM`] and [`MAX_VOXELS`] before anything is
//! allocated, and gzip data is never decompressed past the bytes the header asks for (plus one, to
//! notice extra data), so a lying header or a compression bomb cannot exhaust memory.

use std::fmt;
use std::io::{self, BufRead, BufReader, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::str::FromStr;

use glam::{UVec3, Vec3};

use crate::files::Opened;
use crate::volume::grid::{Grid, MAX_DIM, MAX_VOXELS, voxel_count};

/// The type of the samples in a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScalarType {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    F32,
    F64,
}

/// The byte order of multi-byte samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Endian {
    Little,
    Big,
}

/// What a headerless raw file holds: `dims` samples of `scalar`, x fastest, after `header_bytes`
/// bytes that are skipped.
#[derive(Clone, Debug, PartialEq)]
pub struct RawDesc {
    pub dims: UVec3,
    pub scalar: ScalarType,
    pub spacing: Vec3,
    pub endian: Endian,
    pub header_bytes: u64,
}

const AXES: [&str; 3] = ["x", "y", "z"];
/// The longest header line read (a longer one is not a NRRD header).
const MAX_LINE_BYTES: u64 = 64 * 1024;
/// The most header lines read before giving up on finding the blank line that ends the header.
const MAX_HEADER_LINES: usize = 100_000;
/// Samples converted per chunk while reading binary data.
const CHUNK_SAMPLES: usize = 64 * 1024;
/// The longest number read from ascii data.
const MAX_TOKEN_BYTES: usize = 64;
const ENCODINGS_READ: &str = "Mirador reads raw, gzip and ascii";

impl ScalarType {
    /// Every type.
    pub const ALL: [ScalarType; 8] = [
        ScalarType::U8,
        ScalarType::I8,
        ScalarType::U16,
        ScalarType::I16,
        ScalarType::U32,
        ScalarType::I32,
        ScalarType::F32,
        ScalarType::F64,
    ];

    /// Bytes per sample.
    pub fn size(self) -> usize {
        match self {
            ScalarType::U8 | ScalarType::I8 => 1,
            ScalarType::U16 | ScalarType::I16 => 2,
            ScalarType::U32 | ScalarType::I32 | ScalarType::F32 => 4,
            ScalarType::F64 => 8,
        }
    }

    /// The short name scene files use: `uint8`, `int8`, `uint16`, `int16`, `uint32`, `int32`,
    /// `float32`, `float64`.
    pub fn name(self) -> &'static str {
        self.spellings()[0]
    }

    /// teem's own spelling, written into NRRD headers so that every NRRD reader knows it.
    fn nrrd_name(self) -> &'static str {
        match self {
            ScalarType::U8 => "unsigned char",
            ScalarType::I8 => "signed char",
            ScalarType::U16 => "unsigned short",
            ScalarType::I16 => "short",
            ScalarType::U32 => "unsigned int",
            ScalarType::I32 => "int",
            ScalarType::F32 => "float",
            ScalarType::F64 => "double",
        }
    }

    /// The names read, lower case, words one space apart; the short name first.
    fn spellings(self) -> &'static [&'static str] {
        match self {
            ScalarType::U8 => &["uint8", "uchar", "unsigned char", "uint8_t"],
            ScalarType::I8 => &["int8", "signed char", "int8_t"],
            ScalarType::U16 => &["uint16", "ushort", "unsigned short", "unsigned short int", "uint16_t"],
            ScalarType::I16 => &["int16", "short", "short int", "signed short", "signed short int", "int16_t"],
            ScalarType::U32 => &["uint32", "uint", "unsigned int", "uint32_t"],
            ScalarType::I32 => &["int32", "int", "signed int", "int32_t"],
            ScalarType::F32 => &["float32", "float"],
            ScalarType::F64 => &["float64", "double"],
        }
    }

    /// The value of one sample, `bytes` being exactly [`ScalarType::size`] long.
    fn decode(self, bytes: &[u8], endian: Endian) -> f32 {
        match self {
            ScalarType::U8 => f32::from(bytes[0]),
            ScalarType::I8 => f32::from(bytes[0] as i8),
            ScalarType::U16 => f32::from(u16::from_le_bytes(little_endian(bytes, endian))),
            ScalarType::I16 => f32::from(i16::from_le_bytes(little_endian(bytes, endian))),
            ScalarType::U32 => u32::from_le_bytes(little_endian(bytes, endian)) as f32,
            ScalarType::I32 => i32::from_le_bytes(little_endian(bytes, endian)) as f32,
            ScalarType::F32 => f32::from_le_bytes(little_endian(bytes, endian)),
            ScalarType::F64 => f64::from_le_bytes(little_endian(bytes, endian)) as f32,
        }
    }

    /// Appends `value` as one little-endian sample. Integer types take the nearest integer, and
    /// Rust's float-to-integer `as` clamps it to the type's range.
    fn encode(self, value: f32, out: &mut Vec<u8>) {
        let integer = value.round();
        match self {
            ScalarType::U8 => out.push(integer as u8),
            ScalarType::I8 => out.extend_from_slice(&(integer as i8).to_le_bytes()),
            ScalarType::U16 => out.extend_from_slice(&(integer as u16).to_le_bytes()),
            ScalarType::I16 => out.extend_from_slice(&(integer as i16).to_le_bytes()),
            ScalarType::U32 => out.extend_from_slice(&(integer as u32).to_le_bytes()),
            ScalarType::I32 => out.extend_from_slice(&(integer as i32).to_le_bytes()),
            ScalarType::F32 => out.extend_from_slice(&value.to_le_bytes()),
            ScalarType::F64 => out.extend_from_slice(&f64::from(value).to_le_bytes()),
        }
    }
}

/// `bytes` as an array in little-endian order (reversed when they are big-endian).
fn little_endian<const N: usize>(bytes: &[u8], endian: Endian) -> [u8; N] {
    let mut array = [0; N];
    array.copy_from_slice(bytes);
    if endian == Endian::Big {
        array.reverse();
    }
    array
}

impl fmt::Display for ScalarType {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ScalarType {
    type Err = String;

    /// The short names (`uint8` … `float64`) and NRRD's spellings (`uchar`, `unsigned short int`,
    /// `int16_t`, `double`, …), case-insensitive.
    fn from_str(text: &str) -> Result<ScalarType, String> {
        let wanted = text.split_whitespace().collect::<Vec<_>>().join(" ").to_ascii_lowercase();
        if let Some(scalar) = ScalarType::ALL.into_iter().find(|scalar| scalar.spellings().contains(&wanted.as_str())) {
            return Ok(scalar);
        }
        let accepted = "Mirador reads uint8, int8, uint16, int16, uint32, int32, float32 and float64, \
                        or NRRD's names for them such as `unsigned char`, `short` or `double`";
        // 64-bit integers: `int64`, `uint64_t`, `long long`, `ulonglong`, ….
        if wanted.contains("64") || wanted.contains("long") {
            Err(format!("unsupported type `{text}` ({accepted})"))
        } else {
            Err(format!("unknown type `{text}` ({accepted})"))
        }
    }
}

impl fmt::Display for Endian {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(match self {
            Endian::Little => "little",
            Endian::Big => "big",
        })
    }
}

impl FromStr for Endian {
    type Err = String;

    /// `little` or `big`, case-insensitive.
    fn from_str(text: &str) -> Result<Endian, String> {
        match text.trim().to_ascii_lowercase().as_str() {
            "little" => Ok(Endian::Little),
            "big" => Ok(Endian::Big),
            _ => Err(format!("unknown endian `{text}` (accepted: little, big)")),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Reading NRRD.

/// Reads a NRRD file (attached, or a detached header and its data file) into a grid.
pub fn read_nrrd(path: &Path) -> Result<Grid, String> {
    let file = open_regular(path).map_err(|e| format!("cannot open the file: {e}"))?;
    let mut reader = BufReader::new(file);
    let mut warnings = Vec::new();
    let header = read_header(&mut reader, &mut warnings)?;
    let samples = match &header.data_file {
        None => read_samples(reader, &header, &mut warnings),
        Some(name) => {
            let data_path = path.parent().unwrap_or(Path::new("")).join(name);
            let in_data_file = |e: String| format!("data file {}: {e}", data_path.display());
            open_regular(&data_path)
                .map_err(|e| in_data_file(format!("cannot open it: {e}")))
                .and_then(|file| read_samples(BufReader::new(file), &header, &mut warnings).map_err(in_data_file))
        }
    };
    for warning in &warnings {
        log::warn!("{}: {warning}", path.display());
    }
    Grid::new(header.dims, header.spacing, samples?)
}

/// Opens a volume file, which must be a regular file: a pipe or a device has no size to check the
/// header's against, and might never end.
fn open_regular(path: &Path) -> io::Result<Opened> {
    crate::files::open(path)
}

/// What the header says about the samples.
#[derive(Debug)]
struct Header {
    scalar: ScalarType,
    /// The type as the header spells it, for messages.
    type_text: String,
    dims: UVec3,
    spacing: Vec3,
    encoding: Encoding,
    endian: Endian,
    line_skip: u64,
    byte_skip: ByteSkip,
    /// The detached data file as the header names it (relative to the header's folder).
    data_file: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Raw,
    Gzip,
    Ascii,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ByteSkip {
    Bytes(u64),
    /// `byte skip: -1`: the data is the last bytes of the file (raw only).
    DataAtEnd,
}

/// One `field: value` line.
#[derive(Debug)]
struct Field {
    line: usize,
    value: String,
}

impl Field {
    /// `message` prefixed with this field's line.
    fn error(&self, message: impl fmt::Display) -> String {
        format!("line {}: {message}", self.line)
    }
}

/// The header's fields by name (lower case, spaces removed: `space directions` is
/// `spacedirections`), and whether a blank line ended it.
struct HeaderLines {
    fields: std::collections::HashMap<String, Field>,
    ended_by_blank_line: bool,
}

/// The fields Mirador reads, as [`HeaderLines`] names them.
const FIELDS_READ: [&str; 11] = [
    "type",
    "dimension",
    "sizes",
    "spacings",
    "spacedirections",
    "encoding",
    "endian",
    "lineskip",
    "byteskip",
    "datafile",
    "kinds",
];

/// The other standard fields, read past in silence.
const FIELDS_IGNORED: [&str; 20] = [
    "content",
    "number",
    "blocksize",
    "space",
    "spacedimension",
    "spaceorigin",
    "spaceunits",
    "measurementframe",
    "thicknesses",
    "axismins",
    "axismaxs",
    "centers",
    "centerings",
    "labels",
    "units",
    "min",
    "max",
    "oldmin",
    "oldmax",
    "sampleunits",
];

/// Reads the header, leaving `reader` at the first byte after it.
fn read_header(reader: &mut impl BufRead, warnings: &mut Vec<String>) -> Result<Header, String> {
    let lines = read_header_lines(reader, warnings)?;
    let header = parse_header(&lines, warnings)?;
    if header.data_file.is_none() && !lines.ended_by_blank_line {
        return Err("the header does not end with a blank line, so no data follows it \
                    (and no `data file` field names a file that holds it)"
            .into());
    }
    Ok(header)
}

/// Reads the magic and the header's lines up to the blank line (or the end of the file),
/// keeping the `field: value` lines.
fn read_header_lines(reader: &mut impl BufRead, warnings: &mut Vec<String>) -> Result<HeaderLines, String> {
    let read_error = |e: io::Error| format!("cannot read the header: {e}");
    check_magic(read_line(reader, 64).map_err(read_error)?)?;
    let mut lines = HeaderLines { fields: Default::default(), ended_by_blank_line: false };
    for number in 2.. {
        if number > MAX_HEADER_LINES {
            return Err(format!(
                "the header goes on past {MAX_HEADER_LINES} lines without the blank line that ends it"
            ));
        }
        let Some((bytes, complete)) = read_line(reader, MAX_LINE_BYTES).map_err(read_error)? else { break };
        if !complete {
            return Err(format!("line {number} is longer than {MAX_LINE_BYTES} bytes: this is not a NRRD header"));
        }
        let text = String::from_utf8_lossy(&bytes);
        if text.is_empty() {
            lines.ended_by_blank_line = true;
            break;
        }
        let Some((name, value)) = split_field(&text).map_err(|e| format!("line {number}: {e}"))? else { continue };
        let key: String = name.to_ascii_lowercase().split_whitespace().collect();
        if let Some(first) = lines.fields.get(&key) {
            return Err(format!("line {number}: a second `{name}` field (the first is on line {})", first.line));
        }
        if !FIELDS_READ.contains(&key.as_str()) && !FIELDS_IGNORED.contains(&key.as_str()) {
            warnings.push(format!("line {number}: unknown field `{name}`, ignored"));
        }
        let value = value.trim().to_string();
        // `data file: LIST`: the lines after it name data files (refused by `parse_data_file`).
        let list_follows = key == "datafile" && (value == "LIST" || value.starts_with("LIST "));
        lines.fields.insert(key, Field { line: number, value });
        if list_follows {
            break;
        }
    }
    Ok(lines)
}

/// One line of at most `limit` bytes without its `\n` (or `\r\n`), and whether it was whole
/// (ended by `\n` or the end of the file); `None` at the end of the file.
fn read_line(reader: &mut impl BufRead, limit: u64) -> io::Result<Option<(Vec<u8>, bool)>> {
    let mut bytes = Vec::new();
    reader.by_ref().take(limit + 1).read_until(b'\n', &mut bytes)?;
    if bytes.is_empty() {
        return Ok(None);
    }
    let complete = bytes.last() == Some(&b'\n') || bytes.len() as u64 <= limit;
    if bytes.last() == Some(&b'\n') {
        bytes.pop();
        if bytes.last() == Some(&b'\r') {
            bytes.pop();
        }
    }
    Ok(Some((bytes, complete)))
}

/// The first line must be `NRRD0001` … `NRRD0005`.
fn check_magic(line: Option<(Vec<u8>, bool)>) -> Result<(), String> {
    let Some((magic, _)) = line else { return Err("not a NRRD file: it is empty".into()) };
    if !magic.starts_with(b"NRRD") {
        let start = magic[..magic.len().min(16)].escape_ascii();
        return Err(format!(
            "not a NRRD file: it starts with `{start}`, not with a NRRD magic (`NRRD0001` to `NRRD0005`)"
        ));
    }
    if !matches!(magic.as_slice(), b"NRRD0001" | b"NRRD0002" | b"NRRD0003" | b"NRRD0004" | b"NRRD0005") {
        let magic = magic[..magic.len().min(16)].escape_ascii();
        return Err(format!("unsupported NRRD version `{magic}` (Mirador reads NRRD0001 to NRRD0005)"));
    }
    Ok(())
}

/// A header line's field name and value; `None` for a comment or a `key:=value` line.
fn split_field(line: &str) -> Result<Option<(&str, &str)>, String> {
    if line.starts_with('#') {
        return Ok(None);
    }
    let key_value = line.find(":=");
    let field = line.find(": ").or_else(|| line.find(':').filter(|&at| Some(at) != key_value));
    match (field, key_value) {
        (_, Some(k)) if field.is_none_or(|f| k < f) => Ok(None),
        (Some(f), _) => Ok(Some((&line[..f], &line[f + 1..]))),
        _ => {
            Err(format!("`{}` is neither a `field: value` line, a `key:=value` line nor a `#` comment", excerpt(line)))
        }
    }
}

/// At most 60 characters of `text`, control characters escaped, for messages.
fn excerpt(text: &str) -> String {
    let mut shown = String::new();
    for c in text.chars().take(60) {
        if c.is_control() {
            shown.extend(c.escape_default());
        } else {
            shown.push(c);
        }
    }
    if text.chars().nth(60).is_some() {
        shown.push('…');
    }
    shown
}

/// Interprets the fields: required ones present, values valid, the grid within Mirador's limits.
fn parse_header(lines: &HeaderLines, warnings: &mut Vec<String>) -> Result<Header, String> {
    let optional = |name: &str| lines.fields.get(name);
    let required = |name: &str| optional(name).ok_or_else(|| format!("no `{name}` field in the header"));
    parse_dimension(required("dimension")?)?;
    let type_field = required("type")?;
    let scalar = type_field.value.parse::<ScalarType>().map_err(|e| type_field.error(e))?;
    let dims = parse_sizes(required("sizes")?)?;
    if let Some(kinds) = optional("kinds") {
        check_kinds(kinds)?;
    }
    let encoding = parse_encoding(required("encoding")?)?;
    let endian = match optional("endian") {
        Some(field) => field.value.parse::<Endian>().map_err(|e| field.error(e))?,
        None if scalar.size() > 1 && encoding != Encoding::Ascii => {
            return Err(format!(
                "no `endian` field in the header (a file of {}-byte `{}` samples needs `endian: little` or `endian: big`)",
                scalar.size(),
                type_field.value
            ));
        }
        None => Endian::Little,
    };
    let spacing = match (optional("spacings"), optional("spacedirections")) {
        (Some(spacings), _) => parse_spacings(spacings)?,
        (None, Some(directions)) => parse_space_directions(directions, warnings)?,
        (None, None) => Vec3::ONE,
    };
    let line_skip = match optional("lineskip") {
        Some(field) => field
            .value
            .parse::<u64>()
            .map_err(|_| field.error(format!("line skip must be a whole number, at least 0, got `{}`", field.value)))?,
        None => 0,
    };
    let byte_skip = match optional("byteskip") {
        Some(field) => parse_byte_skip(field, encoding)?,
        None => ByteSkip::Bytes(0),
    };
    let data_file = optional("datafile").map(parse_data_file).transpose()?;
    let type_text = type_field.value.clone();
    Ok(Header { scalar, type_text, dims, spacing, encoding, endian, line_skip, byte_skip, data_file })
}

fn parse_dimension(field: &Field) -> Result<(), String> {
    match field.value.parse::<u64>() {
        Ok(3) => Ok(()),
        Ok(n) => Err(field.error(format!("dimension is {n}, but Mirador reads 3-D scalar volumes (dimension 3)"))),
        Err(_) => Err(field.error(format!("dimension `{}` is not a whole number", field.value))),
    }
}

fn parse_sizes(field: &Field) -> Result<UVec3, String> {
    let words: Vec<&str> = field.value.split_whitespace().collect();
    if words.len() != 3 {
        let noun = if words.len() == 1 { "number" } else { "numbers" };
        return Err(field.error(format!("sizes has {} {noun} but dimension is 3", words.len())));
    }
    let mut sizes = [0; 3];
    for (size, word) in sizes.iter_mut().zip(&words) {
        *size = word.parse().map_err(|_| field.error(format!("sizes: `{word}` is not a whole number")))?;
    }
    checked_dims(sizes).map_err(|e| field.error(e))
}

/// The grid's size, checked before anything is allocated for it: the rules of [`Grid::new`].
fn checked_dims(sizes: [u64; 3]) -> Result<UVec3, String> {
    let [x, y, z] = sizes;
    if sizes.iter().any(|&n| n < 2) {
        return Err(format!("a grid needs at least 2 points on every axis, got {x} × {y} × {z}"));
    }
    // Each size is checked first, so that the product cannot overflow.
    if sizes.iter().any(|&n| n > u64::from(MAX_DIM)) || x * y * z > MAX_VOXELS {
        return Err(format!(
            "a {x} × {y} × {z} grid is larger than Mirador reads ({MAX_DIM} points per axis, {MAX_VOXELS} in all)"
        ));
    }
    Ok(UVec3::new(x as u32, y as u32, z as u32))
}

/// A volume's three axes must be spatial; a colour or vector axis means the file is an image or
/// a vector field, not a scalar volume.
fn check_kinds(field: &Field) -> Result<(), String> {
    for (axis, kind) in AXES.iter().zip(field.value.split_whitespace()) {
        if !matches!(kind.to_ascii_lowercase().as_str(), "domain" | "space" | "time" | "none" | "???") {
            return Err(field.error(format!(
                "the {axis} axis is of kind `{kind}`, but Mirador reads scalar volumes, whose three axes are spatial (`domain`)"
            )));
        }
    }
    Ok(())
}

fn parse_encoding(field: &Field) -> Result<Encoding, String> {
    match field.value.to_ascii_lowercase().as_str() {
        "raw" => Ok(Encoding::Raw),
        "gzip" | "gz" => Ok(Encoding::Gzip),
        "ascii" | "text" | "txt" => Ok(Encoding::Ascii),
        "hex" | "bzip2" | "bz2" | "zrl" => Err(field.error(format!(
            "unsupported encoding `{}` ({ENCODINGS_READ}; teem's `unu save -f nrrd -e gzip` converts a file)",
            field.value
        ))),
        _ => Err(field.error(format!("unknown encoding `{}` ({ENCODINGS_READ})", field.value))),
    }
}

fn parse_spacings(field: &Field) -> Result<Vec3, String> {
    let words: Vec<&str> = field.value.split_whitespace().collect();
    if words.len() != 3 {
        return Err(field.error(format!("spacings has {} entries but dimension is 3", words.len())));
    }
    let mut spacing = [0.0; 3];
    for ((value, word), axis) in spacing.iter_mut().zip(&words).zip(AXES) {
        *value = word.parse::<f32>().map_err(|_| field.error(format!("spacings: `{word}` is not a number")))?;
        if !(value.is_finite() && *value > 0.0) {
            return Err(field.error(format!("the {axis} spacing is `{word}`; spacings must be positive and finite")));
        }
    }
    Ok(Vec3::from_array(spacing))
}

/// The spacing as the lengths of the axes' direction vectors.
fn parse_space_directions(field: &Field, warnings: &mut Vec<String>) -> Result<Vec3, String> {
    let vectors = split_vectors(&field.value).map_err(|e| field.error(format!("space directions: {e}")))?;
    if vectors.len() != 3 {
        return Err(field.error(format!("space directions has {} entries but dimension is 3", vectors.len())));
    }
    let mut spacing = [0.0; 3];
    for (index, (vector, axis)) in vectors.iter().zip(AXES).enumerate() {
        let Some(vector) = vector else {
            return Err(field.error(format!(
                "space directions: the {axis} axis is `none`, but all three axes of a scalar volume are spatial"
            )));
        };
        let length = vector.iter().map(|c| c * c).sum::<f64>().sqrt();
        if !(length.is_finite() && length > 0.0) {
            return Err(field.error(format!(
                "space directions: the {axis} axis's vector has length {length}; it must be positive and finite"
            )));
        }
        if vector.iter().enumerate().any(|(component, &c)| component != index && c != 0.0) {
            warnings.push(format!(
                "line {}: the space directions are not along the axes; Mirador keeps only their lengths, as the spacing",
                field.line
            ));
        }
        spacing[index] = length as f32;
    }
    Ok(Vec3::from_array(spacing))
}

/// `(1,0,0) none (0,0,2.5)` as `[Some([1, 0, 0]), None, Some([0, 0, 2.5])]`.
fn split_vectors(text: &str) -> Result<Vec<Option<Vec<f64>>>, String> {
    let mut vectors = Vec::new();
    let mut rest = text.trim_start();
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix("none") {
            vectors.push(None);
            rest = after.trim_start();
            continue;
        }
        let Some((inside, after)) = rest.strip_prefix('(').and_then(|open| open.split_once(')')) else {
            return Err(format!("expected a vector `(x,y,z)` or `none` at `{}`", excerpt(rest)));
        };
        let components = inside
            .split(',')
            .map(|c| c.trim().parse::<f64>().map_err(|_| format!("`{}` in `({inside})` is not a number", c.trim())))
            .collect::<Result<Vec<f64>, String>>()?;
        vectors.push(Some(components));
        rest = after.trim_start();
    }
    Ok(vectors)
}

fn parse_byte_skip(field: &Field, encoding: Encoding) -> Result<ByteSkip, String> {
    match field.value.parse::<i64>() {
        Ok(-1) if encoding == Encoding::Raw => Ok(ByteSkip::DataAtEnd),
        Ok(-1) => {
            Err(field.error("byte skip -1 (the data is the last bytes of the file) works only with raw encoding"))
        }
        Ok(n) if n >= 0 => Ok(ByteSkip::Bytes(n as u64)),
        _ => Err(field.error(format!("byte skip must be -1 or a whole number at least 0, got `{}`", field.value))),
    }
}

/// One detached data file; the list and numbered-series forms are refused.
fn parse_data_file(field: &Field) -> Result<PathBuf, String> {
    let value = field.value.as_str();
    if value == "LIST" || value.starts_with("LIST ") {
        return Err(
            field.error("`data file: LIST` (a list of data files) is not supported; Mirador reads one data file")
        );
    }
    let words: Vec<&str> = value.split_whitespace().collect();
    if words.len() >= 4 && words[0].contains('%') {
        return Err(field.error(format!(
            "`data file: {value}` names a numbered series of files, which is not supported; Mirador reads one data file"
        )));
    }
    if value.is_empty() {
        return Err(field.error("`data file` names no file"));
    }
    Ok(PathBuf::from(value))
}

impl Header {
    fn count(&self) -> usize {
        voxel_count(self.dims) as usize
    }

    fn byte_count(&self) -> u64 {
        voxel_count(self.dims) * self.scalar.size() as u64
    }

    /// "the data holds 1000 bytes, the header's 10 × 10 × 12 uchar needs 1200", `qualifier`
    /// following "bytes".
    fn short_bytes(&self, held: u64, qualifier: &str) -> String {
        self.too_little(format!("{held} bytes{qualifier}"), self.byte_count())
    }

    /// "the data holds 37 values, the header's 4 × 4 × 4 float needs 64".
    fn short_values(&self, held: usize) -> String {
        self.too_little(format!("{held} values"), self.count() as u64)
    }

    fn too_little(&self, held: String, needed: u64) -> String {
        let UVec3 { x, y, z } = self.dims;
        format!("the data holds {held}, the header's {x} × {y} × {z} {} needs {needed}", self.type_text)
    }

    fn extra_data(&self, what: &str) -> String {
        let UVec3 { x, y, z } = self.dims;
        format!(
            "the data holds more than the header's {x} × {y} × {z} {} needs; the extra {what} ignored",
            self.type_text
        )
    }

    /// The bytes to skip before the data; `byte skip: -1` is refused for all but raw encoding.
    fn bytes_to_skip(&self) -> u64 {
        match self.byte_skip {
            ByteSkip::Bytes(n) => n,
            ByteSkip::DataAtEnd => 0,
        }
    }
}

/// The samples, from the start of the data (after the header, or at the start of the data file).
fn read_samples(
    mut source: BufReader<Opened>,
    header: &Header,
    warnings: &mut Vec<String>,
) -> Result<Vec<f32>, String> {
    for skipped in 0..header.line_skip {
        let read = source.skip_until(b'\n').map_err(|e| format!("cannot read the data: {e}"))?;
        if read == 0 {
            return Err(format!(
                "the data ends after {skipped} lines, before the {} that `line skip` skips",
                header.line_skip
            ));
        }
    }
    match header.encoding {
        Encoding::Raw => read_raw_samples(source, header, warnings),
        Encoding::Gzip => read_gzip_samples(source, header, warnings),
        Encoding::Ascii => read_ascii_samples(source, header, warnings),
    }
}

fn read_raw_samples(
    mut source: BufReader<Opened>,
    header: &Header,
    warnings: &mut Vec<String>,
) -> Result<Vec<f32>, String> {
    let read_error = |e: io::Error| format!("cannot read the data: {e}");
    let position = source.stream_position().map_err(read_error)?;
    let end = crate::files::length(source.get_ref()).map_err(read_error)?;
    let needed = header.byte_count();
    let after_position = end.saturating_sub(position);
    let start = match header.byte_skip {
        ByteSkip::Bytes(skip) if skip > after_position => {
            return Err(format!("byte skip {skip} goes past the end of the data ({after_position} bytes)"));
        }
        ByteSkip::Bytes(skip) => position + skip,
        ByteSkip::DataAtEnd => end.saturating_sub(needed).max(position),
    };
    let held = end - start;
    if held < needed {
        return Err(header.short_bytes(held, ""));
    }
    if held > needed {
        warnings.push(header.extra_data(&format!("{} bytes at its end are", held - needed)));
    }
    source.seek(SeekFrom::Start(start)).map_err(read_error)?;
    read_binary(source.take(needed), header.scalar, header.endian, header.count(), header.count()).map_err(
        |e| match e {
            ReadError::Short(held) => header.short_bytes(held, ""),
            ReadError::Io(e, _) => read_error(e),
        },
    )
}

fn read_gzip_samples(
    source: BufReader<Opened>,
    header: &Header,
    warnings: &mut Vec<String>,
) -> Result<Vec<f32>, String> {
    let skip = header.bytes_to_skip();
    let needed = header.byte_count();
    // Never more than the bytes the header asks for, and one more to notice extra data.
    let mut decompressed = flate2::bufread::GzDecoder::new(source).take(skip.saturating_add(needed).saturating_add(1));
    let skipped = io::copy(&mut decompressed.by_ref().take(skip), &mut io::sink())
        .map_err(|e| gzip_error(e, || format!("the data ends within the byte skip of {skip}")))?;
    if skipped < skip {
        return Err(format!("the data holds {skipped} bytes after decompression, fewer than the byte skip of {skip}"));
    }
    let capacity = header.count().min(CHUNK_SAMPLES * 256);
    let values =
        read_binary(decompressed.by_ref().take(needed), header.scalar, header.endian, header.count(), capacity)
            .map_err(|e| match e {
                ReadError::Short(held) => header.short_bytes(held, " after decompression"),
                ReadError::Io(e, held) => gzip_error(e, || header.short_bytes(held, " after decompression")),
            })?;
    match decompressed.read(&mut [0]) {
        Ok(0) => {}
        Ok(_) => warnings.push(header.extra_data("decompressed bytes are")),
        Err(e) => return Err(gzip_error(e, || "the data ends after the samples, without the gzip checksum".into())),
    }
    Ok(values)
}

/// A decompression error: a stream cut short, described by `cut_short`, or corrupt data.
fn gzip_error(e: io::Error, cut_short: impl FnOnce() -> String) -> String {
    match e.kind() {
        io::ErrorKind::UnexpectedEof => {
            format!("{} (the gzip stream is cut short: the file is truncated)", cut_short())
        }
        _ => format!("the gzip data is corrupt: {e}"),
    }
}

/// Numbers as text, separated by white space (or commas).
fn read_ascii_samples(
    mut source: BufReader<Opened>,
    header: &Header,
    warnings: &mut Vec<String>,
) -> Result<Vec<f32>, String> {
    let read_error = |e: io::Error| format!("cannot read the data: {e}");
    let skip = header.bytes_to_skip();
    let skipped = io::copy(&mut source.by_ref().take(skip), &mut io::sink()).map_err(read_error)?;
    if skipped < skip {
        return Err(format!("byte skip {skip} goes past the end of the data ({skipped} bytes)"));
    }
    let count = header.count();
    let mut values = Vec::with_capacity(count.min(CHUNK_SAMPLES));
    let mut token = Vec::new();
    while values.len() < count {
        if !next_token(&mut source, &mut token).map_err(read_error)? {
            return Err(header.short_values(values.len()));
        }
        if token.len() > MAX_TOKEN_BYTES {
            return Err(format!(
                "data value {} is longer than {MAX_TOKEN_BYTES} characters: not a number",
                values.len()
            ));
        }
        let text = String::from_utf8_lossy(&token);
        let value = text
            .parse::<f64>()
            .map_err(|_| format!("data value {} `{}` is not a number", values.len(), excerpt(&text)))?;
        values.push(value as f32);
    }
    if next_token(&mut source, &mut token).map_err(read_error)? {
        warnings.push(header.extra_data("values are"));
    }
    Ok(values)
}

/// The next run of bytes between white space or commas, into `token`; false at the end of the
/// data. Only the first [`MAX_TOKEN_BYTES`] + 1 bytes are kept, enough to tell that a token is
/// too long to be a number.
fn next_token(source: &mut impl BufRead, token: &mut Vec<u8>) -> io::Result<bool> {
    token.clear();
    loop {
        let buffer = source.fill_buf()?;
        if buffer.is_empty() {
            return Ok(!token.is_empty());
        }
        let mut used = 0;
        let mut ended = false;
        for &byte in buffer {
            used += 1;
            if !(byte.is_ascii_whitespace() || byte == b',') {
                if token.len() <= MAX_TOKEN_BYTES {
                    token.push(byte);
                }
            } else if !token.is_empty() {
                ended = true;
                break;
            }
        }
        source.consume(used);
        if ended {
            return Ok(true);
        }
    }
}

/// Why binary samples could not be read: the data ended after `Short(bytes)`, or reading failed
/// after that many bytes.
enum ReadError {
    Short(u64),
    Io(io::Error, u64),
}

/// `count` samples of `scalar` from `source`, a chunk at a time, each converted to `f32` as it
/// comes (so the file's bytes are never held whole beside the values).
fn read_binary(
    mut source: impl Read,
    scalar: ScalarType,
    endian: Endian,
    count: usize,
    capacity: usize,
) -> Result<Vec<f32>, ReadError> {
    let size = scalar.size();
    let mut values = Vec::with_capacity(capacity);
    let mut chunk = vec![0; CHUNK_SAMPLES.min(count) * size];
    let mut held = 0;
    while values.len() < count {
        let wanted = (count - values.len()).min(CHUNK_SAMPLES) * size;
        let got = fill(&mut source, &mut chunk[..wanted], &mut held)?;
        values.extend(chunk[..got].chunks_exact(size).map(|bytes| scalar.decode(bytes, endian)));
        if got < wanted {
            return Err(ReadError::Short(held));
        }
    }
    Ok(values)
}

/// Reads until `buffer` is full or the data ends; returns the bytes read, counting them into
/// `held` as well.
fn fill(source: &mut impl Read, buffer: &mut [u8], held: &mut u64) -> Result<usize, ReadError> {
    let mut filled = 0;
    while filled < buffer.len() {
        match source.read(&mut buffer[filled..]) {
            Ok(0) => break,
            Ok(n) => {
                filled += n;
                *held += n as u64;
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(ReadError::Io(e, *held)),
        }
    }
    Ok(filled)
}

// ---------------------------------------------------------------------------------------------
// Raw files.

/// Reads a headerless raw file: `desc.header_bytes` skipped, then exactly the grid's samples. A
/// file of any other size is refused, with both sizes in the message.
pub fn read_raw(path: &Path, desc: &RawDesc) -> Result<Grid, String> {
    let dims = checked_dims(desc.dims.to_array().map(u64::from))?;
    let count = voxel_count(dims);
    let needed = count * desc.scalar.size() as u64;
    let file = open_regular(path).map_err(|e| format!("cannot open the file: {e}"))?;
    let held = crate::files::length(&file).map_err(|e| format!("cannot read the file: {e}"))?;
    let total = desc.header_bytes.saturating_add(needed);
    if held != total {
        let grid = format!("{} × {} × {} {} grid", dims.x, dims.y, dims.z, desc.scalar);
        let wanted = match desc.header_bytes {
            0 => format!("a {grid} needs {total}"),
            header => format!("a {header}-byte header and a {grid} need {total}"),
        };
        return Err(format!("the file holds {held} bytes, {wanted} (are the dimensions and the type right?)"));
    }
    let mut reader = BufReader::new(file);
    reader.seek(SeekFrom::Start(desc.header_bytes)).map_err(|e| format!("cannot read the file: {e}"))?;
    let values =
        read_binary(reader, desc.scalar, desc.endian, count as usize, count as usize).map_err(|e| match e {
            ReadError::Short(held) => format!("the file ended after {held} of the grid's {needed} bytes"),
            ReadError::Io(e, _) => format!("cannot read the file: {e}"),
        })?;
    Grid::new(dims, desc.spacing, values)
}

// ---------------------------------------------------------------------------------------------
// Writing NRRD.

/// Writes `grid` as a NRRD0004 file of `scalar` samples (integer types rounded to the nearest
/// integer and clamped to the type's range), little-endian, raw or gzip-compressed. The file is
/// written beside `path` and renamed into place, so a failure never leaves half a file.
pub fn write_nrrd(path: &Path, grid: &Grid, scalar: ScalarType, gzip: bool) -> Result<(), String> {
    let UVec3 { x, y, z } = grid.dims;
    if grid.values.len() as u64 != voxel_count(grid.dims) {
        return Err(format!(
            "a {x} × {y} × {z} grid needs {} values, it has {}",
            voxel_count(grid.dims),
            grid.values.len()
        ));
    }
    let mut samples = Vec::with_capacity(grid.values.len() * scalar.size());
    for &value in &grid.values {
        scalar.encode(value, &mut samples);
    }
    let Vec3 { x: dx, y: dy, z: dz } = grid.spacing;
    let mut header = format!(
        "NRRD0004\n# Written by Mirador: a scalar volume, x fastest.\ntype: {}\ndimension: 3\nsizes: {x} {y} {z}\nspacings: {dx} {dy} {dz}\n",
        scalar.nrrd_name()
    );
    if scalar.size() > 1 {
        header += "endian: little\n";
    }
    header += if gzip { "encoding: gzip\n\n" } else { "encoding: raw\n\n" };
    let mut bytes = header.into_bytes();
    if gzip {
        let mut encoder = flate2::write::GzEncoder::new(bytes, flate2::Compression::default());
        encoder.write_all(&samples).map_err(|e| format!("cannot compress the data: {e}"))?;
        bytes = encoder.finish().map_err(|e| format!("cannot compress the data: {e}"))?;
    } else {
        bytes.extend_from_slice(&samples);
    }
    crate::output::write_atomically(&bytes, path).map_err(|e| format!("cannot write the file: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A fresh, empty folder under the system's temporary folder, unique to this process and call.
    fn temp_dir(name: &str) -> PathBuf {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("mirador-nrrd-unit-{}-{n}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// A 3 × 4 × 5 grid of values every type holds exactly (fractions for the float types).
    fn sample_grid(scalar: ScalarType) -> Grid {
        let dims = UVec3::new(3, 4, 5);
        let values = (0..60)
            .map(|i| {
                let v = match scalar {
                    ScalarType::U8 | ScalarType::U16 | ScalarType::U32 => (i * 4) as f32,
                    ScalarType::I8 | ScalarType::I16 | ScalarType::I32 => (i * 4) as f32 - 120.0,
                    ScalarType::F32 | ScalarType::F64 => i as f32 * 0.375 - 7.0,
                };
                if matches!(scalar, ScalarType::U16 | ScalarType::I16 | ScalarType::U32 | ScalarType::I32) {
                    v * 100.0
                } else {
                    v
                }
            })
            .collect();
        Grid::new(dims, Vec3::new(0.5, 1.0, 2.5), values).unwrap()
    }

    /// A header followed by `data`.
    fn nrrd_bytes(header: &str, data: &[u8]) -> Vec<u8> {
        [header.as_bytes(), data].concat()
    }

    #[test]
    fn every_scalar_type_round_trips_in_both_encodings() {
        let dir = temp_dir("round-trip");
        for scalar in ScalarType::ALL {
            for gzip in [false, true] {
                let grid = sample_grid(scalar);
                let path = dir.join(format!("{scalar}-{gzip}.nrrd"));
                write_nrrd(&path, &grid, scalar, gzip).unwrap();
                assert_eq!(read_nrrd(&path).unwrap(), grid, "{scalar}, gzip {gzip}");
            }
        }
    }

    #[test]
    fn integer_types_round_and_clamp_when_written() {
        let dir = temp_dir("clamp");
        let values = vec![-5.0, 3.6, 300.0, 127.4, 2.5, -0.4, 70000.0, 1e10];
        let grid = Grid::new(UVec3::splat(2), Vec3::ONE, values).unwrap();
        let expect = |scalar: ScalarType| -> Vec<f32> {
            match scalar {
                ScalarType::U8 => vec![0.0, 4.0, 255.0, 127.0, 3.0, 0.0, 255.0, 255.0],
                ScalarType::I8 => vec![-5.0, 4.0, 127.0, 127.0, 3.0, 0.0, 127.0, 127.0],
                ScalarType::U16 => vec![0.0, 4.0, 300.0, 127.0, 3.0, 0.0, 65535.0, 65535.0],
                ScalarType::I16 => vec![-5.0, 4.0, 300.0, 127.0, 3.0, 0.0, 32767.0, 32767.0],
                ScalarType::U32 => vec![0.0, 4.0, 300.0, 127.0, 3.0, 0.0, 70000.0, u32::MAX as f32],
                ScalarType::I32 => vec![-5.0, 4.0, 300.0, 127.0, 3.0, 0.0, 70000.0, i32::MAX as f32],
                ScalarType::F32 | ScalarType::F64 => grid.values.clone(),
            }
        };
        for scalar in ScalarType::ALL {
            let path = dir.join(format!("{scalar}.nrrd"));
            write_nrrd(&path, &grid, scalar, false).unwrap();
            assert_eq!(read_nrrd(&path).unwrap().values, expect(scalar), "{scalar}");
        }
    }

    #[test]
    fn a_big_endian_header_written_by_hand_reads_its_values() {
        let dir = temp_dir("big-endian");
        let values: Vec<i16> = (0..8).map(|i| i * 1000 - 3500).collect();
        let data: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
        let header = "NRRD0005\ntype: signed short int\ndimension: 3\nsizes: 2 2 2\nendian: big\nencoding: raw\n\n";
        let path = dir.join("big.nrrd");
        std::fs::write(&path, nrrd_bytes(header, &data)).unwrap();
        let grid = read_nrrd(&path).unwrap();
        assert_eq!(grid.values, values.iter().map(|&v| f32::from(v)).collect::<Vec<_>>());
        assert_eq!(grid.spacing, Vec3::ONE, "no spacing field: 1 on every axis");

        // The same with 32-bit floats and doubles.
        for (name, data) in [
            ("float", [1.5f32, -2.0].iter().flat_map(|v| v.to_be_bytes()).collect::<Vec<u8>>()),
            ("double", [1.5f64, -2.0].iter().flat_map(|v| v.to_be_bytes()).collect::<Vec<u8>>()),
        ] {
            let header = format!("NRRD0004\ntype: {name}\ndimension: 3\nsizes: 2 2 2\nendian: big\nencoding: raw\n\n");
            let data = data.repeat(4);
            std::fs::write(&path, nrrd_bytes(&header, &data)).unwrap();
            assert_eq!(read_nrrd(&path).unwrap().values, [1.5, -2.0].repeat(4), "{name}");
        }
    }

    #[test]
    fn space_directions_give_the_spacing() {
        let dir = temp_dir("directions");
        let path = dir.join("directions.nrrd");
        let header = "NRRD0004\ntype: uchar\ndimension: 3\nspace: left-posterior-superior\nsizes: 2 2 2\n\
                      space directions: (1,0,0) (0, 0.5 ,0) (0,0,2.5)\nspace origin: (1,2,3)\nencoding: raw\n\n";
        std::fs::write(&path, nrrd_bytes(header, &[0; 8])).unwrap();
        assert_eq!(read_nrrd(&path).unwrap().spacing, Vec3::new(1.0, 0.5, 2.5));

        // Rotated directions: their lengths.
        let rotated = header.replace("(1,0,0) (0, 0.5 ,0)", "(0.6,0.8,0) (-0.8,0.6,0)");
        std::fs::write(&path, nrrd_bytes(&rotated, &[0; 8])).unwrap();
        let spacing = read_nrrd(&path).unwrap().spacing;
        assert!((spacing - Vec3::new(1.0, 1.0, 2.5)).abs().max_element() < 1e-6, "{spacing}");

        // `spacings` wins over directions when both are given.
        let both = header.replace("encoding", "spacings: 3 3 3\nencoding");
        std::fs::write(&path, nrrd_bytes(&both, &[0; 8])).unwrap();
        assert_eq!(read_nrrd(&path).unwrap().spacing, Vec3::splat(3.0));

        // A `none` axis or a zero vector is refused.
        let none = header.replace("(0,0,2.5)", "none");
        std::fs::write(&path, nrrd_bytes(&none, &[0; 8])).unwrap();
        assert!(read_nrrd(&path).unwrap_err().contains("line 6: space directions: the z axis is `none`"));
        let zero = header.replace("(0,0,2.5)", "(0,0,0)");
        std::fs::write(&path, nrrd_bytes(&zero, &[0; 8])).unwrap();
        assert!(read_nrrd(&path).unwrap_err().contains("the z axis's vector has length 0"));
    }

    #[test]
    fn comments_key_values_and_other_fields_are_read_past() {
        let dir = temp_dir("fields");
        let path = dir.join("fields.nrrd");
        let header = "NRRD0004\r\n# a comment: with a colon\r\ncontent: a test\r\nType: UCHAR\r\nDimension: 3\r\n\
                      sizes: 2 2 2\r\nkinds: domain domain domain\r\ncenterings: cell cell cell\r\n\
                      labels: \"x\" \"y\" \"z\"\r\nmin: 0\r\nmax: 7\r\nold min: 0\r\nmeasurement frame: (1,0,0) (0,1,0) (0,0,1)\r\n\
                      modality:=CT: head\r\nfavourite colour: blue\r\nencoding: raw\r\n\r\n";
        std::fs::write(&path, nrrd_bytes(header, &[0, 1, 2, 3, 4, 5, 6, 7])).unwrap();
        let grid = read_nrrd(&path).unwrap();
        assert_eq!(grid.values, [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);

        // A colour axis is not a volume's.
        let colour = header.replace("kinds: domain domain domain", "kinds: RGB-color domain domain");
        std::fs::write(&path, nrrd_bytes(&colour, &[0; 8])).unwrap();
        assert!(read_nrrd(&path).unwrap_err().contains("line 7: the x axis is of kind `RGB-color`"));
    }

    #[test]
    fn byte_skip_line_skip_and_data_at_the_end() {
        let dir = temp_dir("skips");
        let path = dir.join("skips.nrrd");
        let base = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n";
        let data = [10u8, 11, 12, 13, 14, 15, 16, 17];
        let expected: Vec<f32> = data.iter().map(|&v| f32::from(v)).collect();

        let skip = format!("{base}byte skip: 5\n\n");
        std::fs::write(&path, nrrd_bytes(&skip, &[b"junk!".as_slice(), &data].concat())).unwrap();
        assert_eq!(read_nrrd(&path).unwrap().values, expected);

        let lines = format!("{base}line skip: 2\nbyte skip: 1\n\n");
        std::fs::write(&path, nrrd_bytes(&lines, &[b"first\nsecond line\n#".as_slice(), &data].concat())).unwrap();
        assert_eq!(read_nrrd(&path).unwrap().values, expected);

        let at_end = format!("{base}byte skip: -1\n\n");
        std::fs::write(&path, nrrd_bytes(&at_end, &[b"a preamble of any length".as_slice(), &data].concat())).unwrap();
        assert_eq!(read_nrrd(&path).unwrap().values, expected);

        // Past the end, or -1 without raw encoding.
        std::fs::write(&path, nrrd_bytes(&format!("{base}byte skip: 20\n\n"), &data)).unwrap();
        assert!(read_nrrd(&path).unwrap_err().contains("byte skip 20 goes past the end of the data (8 bytes)"));
        let gzip_at_end = at_end.replace("raw", "gzip");
        std::fs::write(&path, nrrd_bytes(&gzip_at_end, &data)).unwrap();
        assert!(read_nrrd(&path).unwrap_err().contains("line 6: byte skip -1"));
    }

    #[test]
    fn gzip_byte_skip_counts_decompressed_bytes() {
        let dir = temp_dir("gzip-skip");
        let path = dir.join("skip.nrrd");
        let mut encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        encoder.write_all(&[99, 99, 99, 1, 2, 3, 4, 5, 6, 7, 8]).unwrap();
        let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: gz\nbyte skip: 3\n\n";
        std::fs::write(&path, nrrd_bytes(header, &encoder.finish().unwrap())).unwrap();
        assert_eq!(read_nrrd(&path).unwrap().values, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
    }

    #[test]
    fn a_detached_header_reads_its_data_file() {
        let dir = temp_dir("detached");
        std::fs::create_dir_all(dir.join("data")).unwrap();
        let values: Vec<u16> = (0..8).map(|i| i * 300).collect();
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(dir.join("data/volume.raw"), &bytes).unwrap();
        // A detached header may end at the end of its file, without a blank line.
        let header = "NRRD0004\ntype: ushort\ndimension: 3\nsizes: 2 2 2\nspacings: 1 1 2\nendian: little\n\
                      encoding: raw\ndata file: ./data/volume.raw";
        std::fs::write(dir.join("volume.nhdr"), header).unwrap();
        let grid = read_nrrd(&dir.join("volume.nhdr")).unwrap();
        assert_eq!(grid.values, values.iter().map(|&v| f32::from(v)).collect::<Vec<_>>());
        assert_eq!(grid.spacing, Vec3::new(1.0, 1.0, 2.0));

        // Gzip-compressed data in a detached file.
        let mut encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        encoder.write_all(&bytes).unwrap();
        std::fs::write(dir.join("data/volume.raw.gz"), encoder.finish().unwrap()).unwrap();
        let gzip = header.replace("encoding: raw", "encoding: gzip").replace("volume.raw", "volume.raw.gz");
        std::fs::write(dir.join("gzip.nhdr"), format!("{gzip}\n\n")).unwrap();
        assert_eq!(read_nrrd(&dir.join("gzip.nhdr")).unwrap(), grid);

        // The list and numbered forms are refused.
        let list = header.replace("./data/volume.raw", "LIST\ndata/volume.raw");
        std::fs::write(dir.join("list.nhdr"), list).unwrap();
        assert!(read_nrrd(&dir.join("list.nhdr")).unwrap_err().contains("line 8: `data file: LIST`"));
        let series = header.replace("./data/volume.raw", "slice%03d.raw 1 2 1");
        std::fs::write(dir.join("series.nhdr"), series).unwrap();
        assert!(read_nrrd(&dir.join("series.nhdr")).unwrap_err().contains("numbered series"));
    }

    #[test]
    fn ascii_encoding_reads_numbers_as_text() {
        let dir = temp_dir("ascii");
        let path = dir.join("ascii.nrrd");
        // Multi-byte types need no endian in text.
        let header = "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nencoding: ascii\n\n";
        std::fs::write(&path, nrrd_bytes(header, b"0 1.5 -2\n3e2,4\n  5 6\t7\n")).unwrap();
        assert_eq!(read_nrrd(&path).unwrap().values, [0.0, 1.5, -2.0, 300.0, 4.0, 5.0, 6.0, 7.0]);

        std::fs::write(&path, nrrd_bytes(header, b"0 1 2 3 4 5 6")).unwrap();
        assert!(
            read_nrrd(&path).unwrap_err().contains("the data holds 7 values, the header's 2 × 2 × 2 float needs 8")
        );
        std::fs::write(&path, nrrd_bytes(header, b"0 1 2 three 4 5 6 7")).unwrap();
        assert!(read_nrrd(&path).unwrap_err().contains("data value 3 `three` is not a number"));
    }

    #[test]
    fn type_and_endian_names_parse() {
        for (names, scalar) in [
            ("uint8 uchar uint8_t", ScalarType::U8),
            ("int8 int8_t", ScalarType::I8),
            ("uint16 ushort uint16_t", ScalarType::U16),
            ("int16 short int16_t", ScalarType::I16),
            ("uint32 uint uint32_t", ScalarType::U32),
            ("int32 int int32_t", ScalarType::I32),
            ("float32 float FLOAT", ScalarType::F32),
            ("float64 double", ScalarType::F64),
        ] {
            for name in names.split(' ') {
                assert_eq!(name.parse::<ScalarType>(), Ok(scalar), "{name}");
            }
            assert_eq!(scalar.name().parse::<ScalarType>(), Ok(scalar));
            assert_eq!(scalar.nrrd_name().parse::<ScalarType>(), Ok(scalar));
        }
        for name in ["unsigned char", "signed char", "short int", "signed short", "signed short int"] {
            assert!(name.parse::<ScalarType>().is_ok(), "{name}");
        }
        for name in ["unsigned short", "unsigned  short  int", "signed int", "unsigned int"] {
            assert!(name.parse::<ScalarType>().is_ok(), "{name}");
        }
        let error = "complex".parse::<ScalarType>().unwrap_err();
        assert!(error.starts_with("unknown type `complex` (Mirador reads uint8, int8,"), "{error}");
        assert!("int64".parse::<ScalarType>().unwrap_err().starts_with("unsupported type `int64`"));
        assert_eq!(ScalarType::ALL.map(ScalarType::size), [1, 1, 2, 2, 4, 4, 4, 8]);
        assert_eq!("Big".parse::<Endian>(), Ok(Endian::Big));
        assert_eq!("little".parse::<Endian>(), Ok(Endian::Little));
        assert_eq!("middle".parse::<Endian>(), Err("unknown endian `middle` (accepted: little, big)".to_string()));
    }

    #[test]
    fn read_raw_reads_headerless_bytes() {
        let dir = temp_dir("raw");
        let path = dir.join("volume.raw");
        let values: Vec<f32> = (0..24).map(|i| i as f32 * 0.25).collect();
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
        std::fs::write(&path, [b"HEADER".as_slice(), &bytes].concat()).unwrap();
        let desc = RawDesc {
            dims: UVec3::new(2, 3, 4),
            scalar: ScalarType::F32,
            spacing: Vec3::new(1.0, 2.0, 3.0),
            endian: Endian::Big,
            header_bytes: 6,
        };
        let grid = read_raw(&path, &desc).unwrap();
        assert_eq!(grid.values, values);
        assert_eq!(grid.spacing, desc.spacing);
        let wrong = RawDesc { header_bytes: 0, ..desc };
        assert_eq!(
            read_raw(&path, &wrong).unwrap_err(),
            "the file holds 102 bytes, a 2 × 3 × 4 float32 grid needs 96 (are the dimensions and the type right?)"
        );
    }
}
