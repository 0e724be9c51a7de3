//! What the tests share.
pub use animats_gpu::bodies::{random_body, Lcg};
