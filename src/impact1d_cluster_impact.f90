!> The joint perfectly inelastic impact of one cluster (issue 19, stage 5; METHOD 8-9): the
!> velocity after is the point of {w : n_k . w >= 0 for every closed row k} nearest to the
!> velocity before v in the kinetic-energy metric,
!>     min 1/2 (w - v).M (w - v)  subject to  n_k . w >= 0,
!> whose optimality conditions are the LCP in the impulses P_k >= 0:
!>     n_k . w = n_k . v + sum_l (n_k M^-1 n_l) P_l >= 0,  P_k (n_k . w) = 0,  w = v + M^-1 N^T P,
!> solved by impact1d_lcp. Called by the N-body event point for a closed group of plastic
!> rows (impact1d_path_impact first, where the rows form a path).
!>
!> What it guarantees (status = lcp_solved):
!> - Nothing changes unless some closed row approaches faster than its rounding level tol_k
!>   (as the two-body engine's impacts did).
!> - w is the projection to rounding; the kinetic energy does not grow (an M-projection onto a
!>   convex cone containing 0).
!> - Exactness: bodies joined by pushed rows that are walls or of the form (-1, 1), (1, -1)
!>   get one velocity exactly: 0 when joined to the ground, else their mean weighted by mass
!>   (a pushed row has n . w = 0).
!> - pushed(k): the rows that took an impulse (P_k above rounding).
!> - No allocation: the caller sizes an impact_work_type once (impact_reserve).
module impact1d_cluster_impact
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_lcp, only: lcp_work_type, lcp_reserve, lcp_solve, lcp_solved, lcp_too_large
  use impact1d_clusters, only: uf_join, group_means, row_coupling, row_rate
  use impact1d_path_impact, only: path_impact_work_type
  implicit none
  private
  public :: impact_work_type, impact_reserve, cluster_projection

  !> The projection's memory, owned by the caller and sized once (impact_reserve).
  type :: impact_work_type
    integer :: max_bodies = 0, max_rows = 0
    !> A group whose rows form a path is projected in O(n) (impact1d_path_impact), the caller
    !> trying it first.
    type(path_impact_work_type) :: path
    type(lcp_work_type) :: lcp
    real(wp), allocatable :: m(:, :)                 !< (max_rows, max_rows) n_k M^-1 n_l over closed rows
    real(wp), allocatable :: q(:), z(:), w(:)        !< (max_rows) n_k . v, impulses, n_k . w
    integer, allocatable :: row_var(:)               !< (max_rows) LCP unknown of closed row k, else 0
    integer, allocatable :: root(:)                  !< (0:max_bodies) union-find, 0 the ground
    real(wp), allocatable :: group_mass(:), group_sum(:)   !< (0:max_bodies) scratch of group_means
  end type impact_work_type

contains

  !> Size the work for clusters of up to max_bodies bodies and max_rows rows.
  subroutine impact_reserve(work, max_bodies, max_rows)
    type(impact_work_type), intent(inout) :: work
    integer, intent(in) :: max_bodies, max_rows
    if (work%max_bodies >= max_bodies .and. work%max_rows >= max_rows .and. allocated(work%m)) return
    if (allocated(work%m)) deallocate(work%m, work%q, work%z, work%w, work%row_var, work%root, &
      work%group_mass, work%group_sum)
    allocate(work%m(max_rows, max_rows), work%q(max_rows), work%z(max_rows), work%w(max_rows), &
      work%row_var(max_rows), work%root(0:max_bodies), work%group_mass(0:max_bodies), &
      work%group_sum(0:max_bodies))
    call lcp_reserve(work%lcp, max_rows)
    work%max_bodies = max_bodies
    work%max_rows = max_rows
  end subroutine impact_reserve

  !> The joint inelastic impact (module header) of bodies 1..size(mass) at velocities
  !> velocity, on the closed rows (ends row_body, 0 = ground; coefficients row_normal); tol:
  !> each row's rounding level of a normal velocity. Out: v_after, impulse (P, 0 off the
  !> closed rows), pushed, status (lcp_solved, else an LCP status and v_after = velocity).
  subroutine cluster_projection(work, mass, velocity, row_body, row_normal, closed, tol, v_after, &
      impulse, pushed, status)
    type(impact_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), velocity(:), row_normal(:, :), tol(:)
    integer, intent(in) :: row_body(:, :)
    logical, intent(in) :: closed(:)
    real(wp), intent(out) :: v_after(:), impulse(:)
    logical, intent(out) :: pushed(:)
    integer, intent(out) :: status
    integer :: k, e, nc
    real(wp) :: p_tol
    logical :: approaching

    v_after(1:size(mass)) = velocity(1:size(mass))
    impulse = 0.0_wp
    pushed = .false.
    status = lcp_too_large
    if (size(mass) > work%max_bodies .or. size(closed) > work%max_rows) return
    status = lcp_solved
    approaching = .false.
    do k = 1, size(closed)
      if (closed(k)) approaching = approaching .or. row_rate(row_body, row_normal, k, velocity) < -tol(k)
    end do
    if (.not. approaching) return
    call build_lcp(work, mass, velocity, row_body, row_normal, closed, nc)
    call lcp_solve(work%lcp, work%m(1:nc, 1:nc), work%q(1:nc), work%z, work%w, status)
    if (status /= lcp_solved) return
    ! Impulses below rounding of the largest (in momentum units) are none.
    p_tol = 0.0_wp
    do e = 1, size(mass)
      p_tol = max(p_tol, mass(e) * abs(velocity(e)))
    end do
    p_tol = 1.0e3_wp * eps_wp * p_tol
    do k = 1, size(closed)
      if (work%row_var(k) == 0) cycle
      impulse(k) = work%z(work%row_var(k))
      if (impulse(k) == 0.0_wp) cycle
      pushed(k) = impulse(k) > p_tol
      do e = 1, 2
        if (row_body(e, k) > 0) v_after(row_body(e, k)) = v_after(row_body(e, k)) + &
          row_normal(e, k) * impulse(k) / mass(row_body(e, k))
      end do
    end do
    call exact_groups(work, mass, row_body, row_normal, pushed, v_after)
  end subroutine cluster_projection

  !> The LCP in the impulses of the closed rows: m(p, l) = n_p M^-1 n_l, q(p) = n_p . v.
  subroutine build_lcp(work, mass, velocity, row_body, row_normal, closed, nc)
    type(impact_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), velocity(:), row_normal(:, :)
    integer, intent(in) :: row_body(:, :)
    logical, intent(in) :: closed(:)
    integer, intent(out) :: nc
    integer :: k
    call row_coupling(mass, row_body, row_normal, closed, work%row_var, nc, work%m)
    do k = 1, size(closed)
      if (work%row_var(k) > 0) work%q(work%row_var(k)) = row_rate(row_body, row_normal, k, velocity)
    end do
  end subroutine build_lcp

  !> Bodies joined by pushed walls and (-1, 1) / (1, -1) rows: one velocity exactly.
  subroutine exact_groups(work, mass, row_body, row_normal, pushed, v_after)
    type(impact_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), row_normal(:, :)
    integer, intent(in) :: row_body(:, :)
    logical, intent(in) :: pushed(:)
    real(wp), intent(inout) :: v_after(:)
    integer :: i, k
    logical :: joined
    do i = 0, size(mass)
      work%root(i) = i
    end do
    do k = 1, size(pushed)
      if (.not. pushed(k)) cycle
      if (row_body(1, k) /= 0 .and. row_body(2, k) /= 0 .and. row_normal(1, k) /= -row_normal(2, k)) cycle
      joined = uf_join(work%root, row_body(1, k), row_body(2, k))
    end do
    call group_means(work%root, mass, v_after, work%group_mass, work%group_sum)
  end subroutine exact_groups
end module impact1d_cluster_impact
