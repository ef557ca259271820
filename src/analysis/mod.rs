//! The analyses of the survey table: Table 2 and the influence of single robots on it
//! ([`table2`]), one relation per class with its slope tests ([`relation`]), speed against
//! size ([`speed`]), designer predictions ([`prediction`]), hypothesis tests
//! ([`inference`]), the scaling-law comparison of Table 1 ([`laws`]) and the live records
//! against a frozen release ([`release_diff`]); the data of the survey figure ([`figure`]). They choose the data from [`crate::dataset`] and take the
//! numbers from [`crate::regression`]; `report/` formats their results.

pub mod figure;
pub mod inference;
pub mod laws;
pub mod prediction;
pub mod relation;
pub mod release_diff;
pub mod speed;
pub mod table2;
