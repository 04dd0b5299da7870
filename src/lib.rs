//! # Shoal — end-to-end simulation of satellite optical instruments over water
//!
//! Shoal simulates the observation chain of an ocean-colour instrument and the retrieval of
//! water products from what it measures, so that an instrument engineer sees what a design
//! choice does to chlorophyll-a, suspended matter, CDOM, depth and bottom type.
//!
//! ```text
//! SceneSpec ─scene─► Scene ─water─► WaterReflectance (a, bb, Kd, rrs, Rrs)   [Lee 1998/1999]
//!                         ─atmosphere─► AtmosphereLut (L_path, T_up, T_down, S, Ed(0+)) [SOS RT]
//!   L_TOA ─instrument─► Level-0 ─calibration─► Level-1 ─correction─► Rrs ─inversion─► products
//!                                                            products + truth ─metrics─► errors
//! ```
//!
//! Modules, in chain order (a module imports only those above it; nothing here imports egui):
//!
//! | module | what it holds |
//! |---|---|
//! | [`colormap`] | viridis, diverging and class colours, value scales (figures and app) |
//! | [`units`] | constants, unit conversions, angle helpers |
//! | [`orbit`] | sun-synchronous orbits (J2), the sun's position, accesses to a site with their geometry |
//! | [`markup`] | the one escaping rule for text inside HTML, SVG and XML |
//! | [`csvtext`] | CSV text: the one writer every table goes through (quoted per RFC 4180) and its reader |
//! | [`infile`] | reading a file someone else made: regular files only, sized before reading, never blocking |
//! | [`variable`] | the product variables (chl-a, NAP, CDOM, depth): keys, names, units, CF names |
//! | [`assets`] | cited spectra embedded in the binary |
//! | [`schema`] | the file formats' version, and files of older versions brought up to date |
//! | [`fields`] | a configuration's fields by path, through serde: numbers read and set, every leaf, what changed, the texts it holds |
//! | [`parse`] | RON parse errors described with line, column and field |
//! | [`ranges`] | the documented range of every number a user sets: one table the validators use |
//! | [`metrics`] | log-space MAE and bias (Seegers et al. 2018), RMSE, R², histograms |
//! | [`control`] | cancellation and progress shared by a run and its watcher |
//! | [`budget`] | what a run may use of the machine (memory, the atmosphere's time), checked before it starts |
//! | [`jobs`] | background work: the newest-request-wins mailbox and the one rayon pool builder |
//! | [`timing`] | timing that can be believed on a noisy machine: wall and CPU time, interleaved repeats paired by round |
//! | [`simd`] | hot loops compiled per instruction-set level (AVX-512, AVX2 + FMA), chosen at run time |
//! | [`geotiff`] | GeoTIFF in and out: rasters with geotransform, CRS, nodata, band names and units |
//! | [`netcdf`] | NetCDF-3 with CF metadata: the variables, writing atomically, reading (line, pixel) maps |
//! | [`spectral`] | wavelength grid, spectra, band sets, `band_from_fine` |
//! | [`water`] | SIOP sets, IOPs, deep/shallow reflectance (Lee et al. 1998/1999, SAMBUCA) |
//! | [`atmosphere`] | Rayleigh, aerosols (Mie, WMO models), gases, SOS radiative transfer, LUT |
//! | [`scene`] | scene files composing water, bottom, land, atmosphere and effects; maps |
//! | [`toa`] | a scene's TOA radiance at any point and view: L_path + T_up·Lw (+ glint, adjacency) |
//! | [`instrument`] | Table 1 instruments: response, pushbroom geometry, PSF, detector, SNR |
//! | [`calibration`] | diffuser and dark frames → per-detector gain and offset; Level-0 → Level-1 |
//! | [`correction`] | Level-1 → Rrs: exact per pixel, and the paper's per-scene approximation |
//! | [`retrieval`] | aLMI and SAMBUCA inversions of band Rrs, improved and as the published codes run |
//! | [`engine`] | the chain as cached stages; the worker thread the app talks to |
//! | [`study`] | studies: runs per instrument and seed, metrics tables, figures (PNG/SVG), cubes; the paper reproduced |
//! | [`sweep`] | sweeps: a study over one parameter or a grid of two, with seeds; shards and merge |
//! | [`season`] | seasons: a design's looks at a site over a period (orbit, glint, clouds), revisit and the product error over the valid looks |
//! | [`design`] | design search: the cheapest design meeting every requirement, and the cost–error front |
//! | [`report`] | the review pack: a study's verdict, figures and provenance as one self-contained HTML page |
//! | [`library`] | the preset library: built-ins and the user's own; atomic saves |
//! | [`validation`] | comparisons with reference codes (OSOAA), shared by tests and `shoal bench` |
//! | `app` | the desktop app (the `gui` feature; the only module that uses egui) |
//! | [`cli`] | the headless command line (`shoal water`, `atmosphere`, `simulate`, `study`, `report`, `reproduce`, `sweep`, `merge`, `budget`, `bench`, `ranges`) |

#[cfg(feature = "gui")]
pub mod app;
pub mod assets;
pub mod atmosphere;
pub mod budget;
pub mod calibration;
pub mod cli;
pub mod colormap;
pub mod control;
pub mod correction;
pub mod csvtext;
pub mod design;
pub mod engine;
pub mod fields;
pub mod geotiff;
pub mod infile;
pub mod instrument;
pub mod jobs;
pub mod library;
pub mod markup;
pub mod metrics;
pub mod netcdf;
pub mod orbit;
pub mod parse;
pub mod ranges;
pub mod report;
pub mod retrieval;
pub mod scene;
pub mod schema;
pub mod season;
pub mod simd;
pub mod spectral;
pub mod study;
pub mod sweep;
pub mod timing;
pub mod toa;
pub mod units;
pub mod validation;
pub mod variable;
pub mod water;
