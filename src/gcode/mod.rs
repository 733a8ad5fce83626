//! G-code writer (placeholder: the G-code helper replaces this).
