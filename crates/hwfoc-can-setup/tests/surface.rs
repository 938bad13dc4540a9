//! The public surface of `hwfoc-can-setup`: this list is the API (as `hwfoc-io`'s
//! `tests/surface.rs` is that crate's): the test does not compile when an item goes missing or
//! moves.

#![allow(unused_imports)]

use hwfoc_can_setup::{Change, Client, EscSurvey, Heard, Link, NodeHeard, SetupError, Survey};
use hwfoc_can_setup::{Direction, LED_COLORS, Led, StatusMessage, ThrottleSource};
use hwfoc_can_setup::{Made, Motion, rate_text, short_name};
use hwfoc_can_setup::{REQUEST_PRIORITY, baud_code, parse_rate, rate_code, rate_hz};
