//! A value made before the UI is laid out (so that the layout only draws it), from inputs, and
//! kept while they stay the same: the volume probe and the lat–long marker under the cursor.

/// The value made from the last inputs; `None` inputs make no value.
pub struct Kept<I, T> {
    inputs: Option<I>,
    value: Option<T>,
}

impl<I, T> Default for Kept<I, T> {
    fn default() -> Self {
        Kept { inputs: None, value: None }
    }
}

impl<I: PartialEq, T> Kept<I, T> {
    /// Makes the value for `inputs` with `make`, unless the one kept was made from the same.
    pub fn update(&mut self, inputs: Option<I>, make: impl FnOnce(&I) -> T) {
        if inputs != self.inputs {
            self.value = inputs.as_ref().map(make);
            self.inputs = inputs;
        }
    }

    /// Whether the kept value is the one [`Self::update`] would make from `inputs`.
    pub(in crate::viewer) fn is_current(&self, inputs: &Option<I>) -> bool {
        *inputs == self.inputs
    }

    pub fn get(&self) -> Option<&T> {
        self.value.as_ref()
    }
}
