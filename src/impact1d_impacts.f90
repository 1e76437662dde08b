!> Impact laws: Newton restitution on one contact, applied as an impulse along M^-1 n so
!> that momentum is kept by slot impacts and a wall only reverses its body's velocity.
!> A kernel of the pair (impact1d_lanes): velocities in lanes, the pair's masses and
!> normals (scene%pair, the mode kernel's view: a one-body scene's idle lane has unit mass
!> and no normal, so it keeps its velocity 0).
module impact1d_impacts
  use impact1d_kinds, only: wp
  use impact1d_lanes, only: max_lanes
  use impact1d_scene, only: scene_type
  use impact1d_modes, only: pair_rows
  implicit none
  private
  public :: normal_velocity, impulse, most_approaching, restitution_of, kinetic_energy, &
    joint_inelastic, inelastic_projection, both_limits_closed

contains

  !> Rate of change of gap k.
  pure real(wp) function normal_velocity(scene, k, v)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    real(wp), intent(in) :: v(max_lanes)
    normal_velocity = dot_product(scene%pair%normal(:, k), v)
  end function normal_velocity

  !> Velocities after an impulse on contact k that leaves the normal velocity at -r times
  !> its value before. For the slot this is the tutorial's two-body formula; for a wall v' = -r v.
  !> With rigid (the bodies locked by a rigid link) a wall stops or throws back both as one
  !> body of mass m1 + m2, the link carrying the impulse: the pair's velocity is its centre of
  !> mass's (a relative velocity the link cannot have is absorbed, as by a plastic link
  !> impact), and the wall reverses that: v' = v_cm - (1 + r) u_cm n_i for both.
  pure subroutine impulse(scene, k, r, v, v_after, rigid)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    real(wp), intent(in) :: r, v(max_lanes)
    real(wp), intent(out) :: v_after(max_lanes)
    logical, intent(in), optional :: rigid
    real(wp) :: p, v_pair
    if (present(rigid)) then
      if (rigid .and. scene%row_body(1, k) == 0) then
        ! Written so that it is v(1) to the bit when the bodies already move together.
        v_pair = v(1) + scene%pair%mass(2) * (v(2) - v(1)) / sum(scene%pair%mass)
        v_after = v_pair - (1.0_wp + r) * normal_velocity(scene, k, [v_pair, v_pair]) * sum(scene%pair%normal(:, k))
        return
      end if
    end if
    p = -(1.0_wp + r) * normal_velocity(scene, k, v) / dot_product(scene%pair%normal(:, k)**2, 1.0_wp / scene%pair%mass)
    v_after = v + scene%pair%normal(:, k) * p / scene%pair%mass
    ! A wall acts on its own body only: keep the other velocity bit for bit.
    where (scene%pair%normal(:, k) == 0.0_wp) v_after = v
  end subroutine impulse

  !> The closed contact approaching fastest (0 if none approaches faster than its tol; the
  !> first in row order among equals).
  pure integer function most_approaching(scene, closed, v, tol) result(k_best)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: closed(pair_rows)
    real(wp), intent(in) :: v(max_lanes), tol(pair_rows)
    integer :: k
    real(wp) :: u_best
    k_best = 0
    u_best = 0.0_wp
    do k = 1, scene%n_rows
      if (.not. closed(k)) cycle
      if (normal_velocity(scene, k, v) < min(u_best, -tol(k))) then
        k_best = k
        u_best = normal_velocity(scene, k, v)
      end if
    end do
  end function most_approaching

  !> Restitution used for row k. When both limits of its record are closed at once (a rigid
  !> link, d_min = d_max: the event point closes a row_partner with its row) the link has no
  !> room to rebound: the bodies move as one (r = 0), where elastic limits would otherwise
  !> exchange the relative velocity forever in zero time.
  pure real(wp) function restitution_of(scene, k, closed)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    logical, intent(in) :: closed(pair_rows)
    restitution_of = scene%row_restitution(k)
    if (both_limits_closed(scene, k, closed)) restitution_of = 0.0_wp
  end function restitution_of

  !> Whether row k and the other limit of its record (rows of one record are adjacent) are
  !> both closed.
  pure logical function both_limits_closed(scene, k, closed)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    logical, intent(in) :: closed(pair_rows)
    integer :: j
    both_limits_closed = .false.
    do j = max(k - 1, 1), min(k + 1, scene%n_rows)
      if (j /= k .and. scene%row_contact(j) == scene%row_contact(k)) both_limits_closed = closed(k) .and. closed(j)
    end do
  end function both_limits_closed

  !> Whether the impact at this instant is one joint projection (inelastic_projection) rather
  !> than a sequence of impulses: two or more contacts are closed and every one of them is
  !> perfectly inelastic (as restitution_of sees it). A rigid link's two limits are one
  !> constraint, which a single impulse already resolves exactly: they keep that path.
  pure logical function joint_inelastic(scene, closed)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: closed(pair_rows)
    integer :: k
    joint_inelastic = count(closed) > 1
    do k = 1, scene%n_rows
      joint_inelastic = joint_inelastic .and. .not. both_limits_closed(scene, k, closed)
    end do
    do k = 1, scene%n_rows
      if (closed(k)) joint_inelastic = joint_inelastic .and. restitution_of(scene, k, closed) == 0.0_wp
    end do
  end function joint_inelastic

  !> A simultaneous, perfectly inelastic impact on the closed contacts, solved jointly: the
  !> velocity after is the point of {w : n_k . w >= 0 for every closed k} nearest to v in the
  !> kinetic-energy metric (METHOD: Moreau's impact law with r = 0). Sequential impulses only
  !> approach it geometrically (a body pinned between a wall and a heavier body). In two
  !> dimensions the nearest point has at most two independent active faces, so it is one of:
  !> v itself, v projected onto one face, or the vertex of two independent faces, which is
  !> w = 0. The nearest feasible candidate is the projection (any feasible point is at least
  !> as far as the projection, and the projection is among the candidates).
  !> tol: rounding level of each contact's normal velocity (feasibility within it).
  !> pushed: the contacts whose face the projection lies on (they take an impulse).
  pure subroutine inelastic_projection(scene, closed, v, tol, v_after, pushed)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: closed(pair_rows)
    real(wp), intent(in) :: v(max_lanes), tol(pair_rows)
    real(wp), intent(out) :: v_after(max_lanes)
    logical, intent(out) :: pushed(pair_rows)
    real(wp) :: candidate(max_lanes), distance, best_distance
    integer :: j, k

    v_after = v
    pushed = .false.
    if (most_approaching(scene, closed, v, tol) == 0) return
    best_distance = huge(1.0_wp)
    do k = 1, scene%n_rows
      if (.not. closed(k)) cycle
      do j = k, scene%n_rows
        if (.not. closed(j)) cycle
        if (j == k) then
          ! The single-face projection is the r = 0 impulse (exact for a wall: its body stops).
          call impulse(scene, k, 0.0_wp, v, candidate)
        else
          ! Opposite normals (a rigid link's two limits) span one line only: no vertex.
          associate (n => scene%pair%normal)
            if (n(1, j) * n(2, k) - n(2, j) * n(1, k) == 0.0_wp) cycle
          end associate
          candidate = 0.0_wp
        end if
        if (most_approaching(scene, closed, candidate, tol) /= 0) cycle
        distance = dot_product(scene%pair%mass, (candidate - v)**2)
        if (distance >= best_distance) cycle
        best_distance = distance
        v_after = candidate
        pushed = .false.
        pushed(k) = .true.
        pushed(j) = .true.
      end do
    end do
  end subroutine inelastic_projection

  !> Kinetic energy of the bodies at velocities v: N of them, or lanes (an idle lane adds +0).
  pure real(wp) function kinetic_energy(scene, v)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: v(:)
    integer :: i
    kinetic_energy = 0.0_wp
    do i = 1, size(v)
      kinetic_energy = kinetic_energy + scene%pair%mass(i) * v(i)**2
    end do
    kinetic_energy = 0.5_wp * kinetic_energy
  end function kinetic_energy
end module impact1d_impacts
