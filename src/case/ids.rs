//! Typed ids: what the names of a case file resolve to. Validation resolves the names of the
//! sections once and stores the ids in the [`super::Case`] it makes; the modules past it look
//! tables up by id, a lookup that cannot fail. The names of `[verification]`, whose kinds the case
//! does not know, its check resolves into ids of its own with the same lookups
//! ([`super::CaseFile::body_named`] and the like), which validation has seen succeed.

macro_rules! id {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub struct $name(usize);

        impl $name {
            /// The id of the table at `index` of its array in the case file (made by validation,
            /// which knows the index exists).
            pub(crate) fn new(index: usize) -> Self {
                $name(index)
            }

            /// The table's index in its array of the case file.
            pub fn index(self) -> usize {
                self.0
            }
        }
    };
}

id!(
    /// A `[[materials]]` table.
    MaterialId
);
id!(
    /// A `[[bodies]]` table; also the `body` number of its material points.
    BodyId
);
id!(
    /// A `[[loads]]` table.
    LoadId
);
id!(
    /// A `[[boundaries]]` table.
    BoundaryId
);
id!(
    /// A `[[time_functions]]` table.
    TimeFunctionId
);
id!(
    /// A `[[stages]]` table.
    StageId
);

/// The names of a case resolved, table by table (each vector in the order of its array).
#[derive(Debug, Clone)]
pub(crate) struct Links {
    /// The material of each body.
    pub body_materials: Vec<MaterialId>,
    /// What each boundary names.
    pub boundaries: Vec<BoundaryLinks>,
    /// What each load names.
    pub loads: Vec<LoadLinks>,
    /// Each body's initial fields, parsed.
    pub body_initial: Vec<super::schema::InitialValues>,
}

/// What a boundary names.
#[derive(Debug, Clone)]
pub(crate) struct BoundaryLinks {
    /// The body of its moving surface.
    pub surface_body: Option<BodyId>,
    /// Its time function.
    pub time_function: Option<TimeFunctionId>,
}

/// What a load names.
#[derive(Debug, Clone)]
pub(crate) struct LoadLinks {
    /// The bodies it is limited to (a particle traction's `body`, a body force's `bodies`).
    pub bodies: Option<Vec<BodyId>>,
    /// Its time function.
    pub time_function: Option<TimeFunctionId>,
}
