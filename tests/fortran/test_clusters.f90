!> Cluster bookkeeping (impact1d_clusters): after every one of 20,000 random closings and
!> releases of rows among 30 bodies, the clusters are the connected components of the closed
!> body-body rows recomputed from scratch, and the member lists are consistent; and a chain
!> split and joined by hand, with a rigid link's two rows between one pair.
program test_clusters
  use impact1d_clusters, only: cluster_set_type, clusters_build, clusters_close, clusters_open, uf_join, uf_find
  use testing, only: check, finish, seed_random
  implicit none
  integer, parameter :: n = 30, nr = 60, steps = 20000
  type(cluster_set_type) :: set
  integer :: row_body(2, nr), k, step, wrong
  real :: u(3)

  call seed_random(31337, 11)
  do k = 1, nr
    call random_number(u)
    row_body(2, k) = 1 + int(n * u(1))
    row_body(1, k) = int((n + 1) * u(2))          ! 0: a wall (the ground)
    if (row_body(1, k) == row_body(2, k)) row_body(1, k) = 0
    if (u(3) < 0.1 .and. k > 1) row_body(:, k) = row_body(:, k - 1)   ! a second row between one pair
  end do
  call clusters_build(set, n, row_body)
  wrong = 0
  do step = 1, steps
    call random_number(u)
    k = 1 + int(nr * u(1))
    if (set%closed(k)) then
      call clusters_open(set, k)
    else
      call clusters_close(set, k)
    end if
    if (.not. consistent(set, row_body)) wrong = wrong + 1
  end do
  call check(wrong == 0, 'random closings and releases: the clusters are the connected components')
  call chain_by_hand()
  call finish('test_clusters')

contains

  !> Whether set's clusters are the components of its closed body-body rows (a union-find
  !> from scratch), each member list holds its cluster's bodies and sizes, ids are unique.
  logical function consistent(set, row_body)
    type(cluster_set_type), intent(in) :: set
    integer, intent(in) :: row_body(:, :)
    integer :: root(0:n), to_id(0:n), to_root(n), i, j, c, r, members
    logical :: joined
    root = [(i, i = 0, n)]
    do k = 1, size(row_body, 2)
      if (set%closed(k) .and. all(row_body(:, k) > 0)) joined = uf_join(root, row_body(1, k), row_body(2, k))
    end do
    to_id = 0
    to_root = -1
    consistent = .true.
    do i = 1, n
      r = uf_find(root, i)
      c = set%cluster_of(i)
      if (to_id(r) == 0) to_id(r) = c
      if (to_root(c) == -1) to_root(c) = r
      consistent = consistent .and. to_id(r) == c .and. to_root(c) == r
    end do
    members = 0
    do c = 1, n
      j = set%first(c)
      i = 0
      do while (j /= 0)
        consistent = consistent .and. set%cluster_of(j) == c
        i = i + 1
        j = set%next(j)
      end do
      consistent = consistent .and. i == set%size(c)
      members = members + i
    end do
    consistent = consistent .and. members == n .and. count(set%first(1:n) == 0) == set%n_free
  end function consistent

  !> A chain 1-2-3-4-5 with two rows between 2 and 3 (a rigid link's limits) and a wall on 1.
  subroutine chain_by_hand()
    type(cluster_set_type) :: chain
    integer, parameter :: body(2, 6) = reshape([1, 2, 2, 3, 2, 3, 3, 4, 4, 5, 0, 1], [2, 6])
    call clusters_build(chain, 5, body)
    do k = 1, 6
      call clusters_close(chain, k)
    end do
    call check(all(chain%cluster_of == chain%cluster_of(1)) .and. chain%size(chain%cluster_of(1)) == 5, &
      'chain closed: one cluster of 5 (the wall joins nothing)')
    call clusters_open(chain, 2)
    call check(all(chain%cluster_of == chain%cluster_of(1)), 'one of two rows between 2 and 3 released: still one')
    call clusters_open(chain, 4)
    call check(all(chain%cluster_of(1:3) == chain%cluster_of(1)) .and. all(chain%cluster_of(4:5) == chain%cluster_of(4)) &
      .and. chain%cluster_of(1) /= chain%cluster_of(4) .and. chain%size(chain%cluster_of(4)) == 2, &
      'row 3-4 released: {1, 2, 3} and {4, 5}')
    call clusters_open(chain, 6)
    call check(chain%size(chain%cluster_of(1)) == 3, 'the wall released: no change')
    call clusters_close(chain, 4)
    call check(all(chain%cluster_of == chain%cluster_of(5)) .and. chain%n_free == 4, 'row 3-4 closed again: one cluster')
  end subroutine chain_by_hand
end program test_clusters
