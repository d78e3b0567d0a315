//! The `#define`s injected into a kernel after its `#version`: below the program that injects
//! them and the binding-slot table (`slots`) that is one of them.

use std::collections::BTreeMap;

/// `#define NAME VALUE` lines injected after `#version`, in name order.
#[derive(Debug, Clone, Default)]
pub struct Defines(pub BTreeMap<String, String>);

impl Defines {
    pub fn new() -> Self {
        Self::default()
    }
    pub fn set(mut self, name: &str, value: impl ToString) -> Self {
        self.0.insert(name.to_string(), value.to_string());
        self
    }
}
