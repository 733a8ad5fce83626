//! The paper's test part (placeholder).
