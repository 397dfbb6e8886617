//! The run hash: everything that determines the result of one run, hashed.

use super::{Block, Campaign, Contact, Engine, Loading, MeshLevel, Needle, PoseSpec, Solver, Tissue};
use serde::Serialize;
use sha2::{Digest, Sha256};

impl Campaign {
    /// Hash of everything that determines the result of one run: the whole spec except
    /// the pose list and description, plus this pose and the mesh level. Hex SHA-256.
    pub fn run_hash(&self, pose: &PoseSpec, mesh_name: &str) -> String {
        self.hash_with(pose, mesh_name, self.mesh.get(mesh_name), &self.solver, None)
    }

    /// Hash of everything that determines a run solved by its first attempt: as
    /// [`run_hash`](Self::run_hash), without the settings only later attempts of the
    /// FEBio retry ladder use (`retry_dtol`, `retry_rtol`, `retry_min_residual_n`, also a
    /// level's own: the continuations and the quarter-step attempts;
    /// `last_attempt_penalty_scale`: the fifth attempt), and marked
    /// so that it never equals a `run_hash`. A run whose first attempt solved it is
    /// reproduced by the spec as long as this hash stays the same, whatever the ladder's
    /// later rungs become (the manifest's `first_attempt_hash`,
    /// [`Manifest::current_entry`](crate::manifest::Manifest::current_entry)).
    /// On a level whose first attempt uses the retries' tolerances
    /// ([`MeshLevel::retry_tolerances_first`]) those stay in this hash.
    pub fn first_attempt_hash(&self, pose: &PoseSpec, mesh_name: &str) -> String {
        let mut solver = self.solver.clone();
        let level = self.mesh.get(mesh_name);
        if !level.is_some_and(MeshLevel::retry_tolerances_first) {
            solver.febio.retry_dtol = 0.0;
            solver.febio.retry_rtol = 0.0;
            solver.febio.retry_min_residual_n = 0.0;
        }
        solver.febio.last_attempt_penalty_scale = 0.0;
        let level = level.map(|m| {
            if m.retry_tolerances_first() {
                m.clone()
            } else {
                MeshLevel { retry_rtol: None, retry_min_residual_n: None, ..m.clone() }
            }
        });
        self.hash_with(pose, mesh_name, level.as_ref(), &solver, Some("first attempt"))
    }

    fn hash_with(&self, pose: &PoseSpec, mesh_name: &str, mesh: Option<&MeshLevel>, solver: &Solver, scope: Option<&str>) -> String {
        #[derive(Serialize)]
        struct Key<'a> {
            tissue: &'a Tissue,
            needle: &'a Needle,
            block: &'a Block,
            contact: &'a Contact,
            loading: &'a Loading,
            mesh_name: &'a str,
            mesh: Option<&'a MeshLevel>,
            pose: &'a PoseSpec,
            generator: u32,
            #[serde(skip_serializing_if = "Option::is_none")]
            solver: Option<&'a Solver>,
            #[serde(skip_serializing_if = "Option::is_none")]
            scope: Option<&'a str>,
        }
        let key = Key {
            tissue: &self.tissue,
            needle: &self.needle,
            block: &self.block,
            contact: &self.contact,
            loading: &self.loading,
            mesh_name,
            mesh,
            pose,
            generator: match self.solver.engine {
                Engine::Ccx => crate::versions::CCX_DECK,
                Engine::Febio => crate::versions::FEBIO_INPUT,
            },
            solver: (solver.engine != Engine::Ccx).then_some(solver),
            scope,
        };
        // plain data with string keys: serialising cannot fail; if it ever did, an empty
        // key would give every run the same hash, so fail loudly instead
        let json = serde_json::to_string(&key).unwrap_or_else(|e| panic!("the spec hash key does not serialise: {e}"));
        hex(&Sha256::digest(json.as_bytes()))
    }
}

/// Lower-case hex of a byte string.
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}
